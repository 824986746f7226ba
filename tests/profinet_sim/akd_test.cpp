// The controller's CmClient and cyclic engines against simulated AKD and generic IO devices: the
// telegram picked by the expected submodule, data both ways, the PROFIdrive state machine to S4,
// a record-47 parameter read, the device's watchdog, power loss, a wrong module, no allocation
// (alarms included).
#include <gtest/gtest.h>

#include "profiles/profidrive/param_access.hpp"
#include "tests/profinet_sim/sim_bench.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet::test {
namespace {

namespace pd = profidrive;

constexpr std::uint16_t be16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}
void put16(std::span<std::uint8_t> b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v >> 8);
  b[at + 1] = static_cast<std::uint8_t>(v & 0xFF);
}

// One AKD (persona configured with telegram 1) and one generic IO device on the network.
struct Line {
  Line() {
    akd = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    io = std::make_unique<GenericIoPersona>(GenericIoPersonaConfig{
        {{0, 0, 0x10, {{1, 0x10, 0, 0}}}, {0, 1, 0x20, {{1, 0x21, 2, 0}}}, {0, 2, 0x30, {{1, 0x31, 0, 4}}}},
        0x0042,
        "IO-1",
        "1"});
    drive = &bench.net.add(device_config(1, "drive-a", suite(11)), *akd);
    iodev = &bench.net.add(device_config(2, "io-b", suite(12)), *io);
  }
  std::unique_ptr<AkdPersona> akd;
  std::unique_ptr<GenericIoPersona> io;
  PnDevice* drive = nullptr;
  PnDevice* iodev = nullptr;
  SimBench bench;
};

bool in_data_exchange(const SimBench::Ar& ar) { return ar.cm->state() == CmClientState::DataExchange; }

TEST(PnSimAkd, Telegram1ConnectsAndDataFlowsBothWays) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  EXPECT_EQ(ar.cm->module_diff(), "");
  EXPECT_EQ(l.akd->telegram(), 1);
  EXPECT_EQ(l.drive->ar_state(), CmServerState::DataExchange);
  l.bench.run_for(100ms);
  // The device's input CR runs: the controller takes ZSW1 (S1 0x0240 with bit 9 set, §9.4).
  ASSERT_EQ(plan.consumer->state(), RtConsumerState::Running) << plan.consumer->reason();
  EXPECT_TRUE(plan.consumer->all_iops_good());
  const std::size_t tg = plan.index(1);
  EXPECT_EQ(be16(plan.consumer->data(tg), 0) & 0x0240, 0x0240);
  // The controller's outputs arrive: STW1 0x047E puts the drive into S2 (ready to switch on).
  put16(plan.provider->data(tg), 0, 0x047E);
  l.bench.run_for(100ms);
  EXPECT_EQ(l.akd->drive().state(), pd::sim::State::S2ReadyForSwitchingOn);
  EXPECT_EQ(l.drive->output_cr()->state(), RtConsumerState::Running);
  // 16 ms update time (send clock 1 ms x 16, the AKD's fastest, §2): about 6 frames per 100 ms.
  EXPECT_GE(plan.consumer->counters().frames, 10U);
}

TEST(PnSimAkd, Stw1SequenceBringsTheDriveToOperation) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  const std::size_t tg = plan.index(1);
  auto zsw1 = [&] { return be16(plan.consumer->data(tg), 0); };
  put16(plan.provider->data(tg), 0, 0x047E);  // OFF1: S2
  ASSERT_TRUE(l.bench.run_until([&] { return zsw1() == 0x0231; }, 1s)) << std::hex << zsw1();
  put16(plan.provider->data(tg), 0, 0x047F);  // ON + enable operation: S3, then S4
  ASSERT_TRUE(l.bench.run_until([&] { return (zsw1() & 0x0237) == 0x0237; }, 1s)) << std::hex << zsw1();
  EXPECT_EQ(l.akd->drive().state(), pd::sim::State::S4Operation);
  // Speed setpoint 1000 rpm (NSOLL_A 2^14 = 6000 rpm... 2^15 = 12000 rpm: 2731) and the drive follows.
  put16(plan.provider->data(tg), 2, 2731);
  l.bench.run_for(500ms);
  EXPECT_NEAR(static_cast<double>(static_cast<std::int16_t>(be16(plan.consumer->data(tg), 2))), 2731.0, 30.0);
  EXPECT_EQ(zsw1() & 0x0400, 0x0400) << std::hex << zsw1();  // at the setpoint
}

TEST(PnSimAkd, ExpectedSubmoduleSelectsTelegram9) {
  Line l;
  ArPlan plan(akd_plan(9, 10, 20), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  EXPECT_EQ(ar.cm->module_diff(), "");
  EXPECT_EQ(l.akd->telegram(), 9);
  EXPECT_EQ(l.akd->drive().layout().number, 9);
  EXPECT_EQ(l.akd->drive().operating_mode(), pd::sim::OperatingMode::Position);
  l.bench.run_for(100ms);
  EXPECT_EQ(plan.consumer->data(plan.index(1)).size(), 10U);
  EXPECT_EQ(be16(plan.consumer->data(plan.index(1)), 0) & 0x0240, 0x0240);
}

TEST(PnSimAkd, TelegramWithOtherLengthsIsRefused) {
  Line l;
  ArPlan plan(akd_plan(9, 4, 4), ip_of(11), device_mac(1), 0);  // telegram 9 is 10 in / 20 out
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return ar.cm->state() == CmClientState::Failed; }, 5s));
  EXPECT_NE(ar.cm->reason().find("ExpectedSubmoduleBlockReq"), std::string_view::npos) << ar.cm->reason();
  EXPECT_EQ(l.drive->ar_state(), CmServerState::NoAr);
  EXPECT_EQ(l.drive->counters().connects_refused, 1U);
}

TEST(PnSimAkd, UpdateTimeBelow16MsIsRefused) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0, 8);  // 1 ms x 8
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return ar.cm->state() == CmClientState::Failed; }, 5s));
  EXPECT_NE(ar.cm->reason().find("IOCRBlockReq"), std::string_view::npos) << ar.cm->reason();
  EXPECT_EQ(l.drive->ar_state(), CmServerState::NoAr);
}

TEST(PnSimAkd, IocrLayoutOtherThanTheDevicesIsRefused) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  plan.config.connect.input.data_length = 44;  // the objects end at 7: the C_SDU is 40
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return ar.cm->state() == CmClientState::Failed; }, 5s));
  EXPECT_NE(ar.cm->reason().find("IOCRBlockReq"), std::string_view::npos) << ar.cm->reason();
  EXPECT_EQ(l.drive->ar_state(), CmServerState::NoAr);
  EXPECT_EQ(l.drive->input_cr(), nullptr);
}

TEST(PnSimAkd, WrongModuleInSlot1IsReportedByModuleDiff) {
  Line l;
  auto subs = akd_plan(1, 4, 4);
  subs[1].module = 0x0777;  // no telegram module has this ident
  ArPlan plan(subs, ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return ar.cm->state() == CmClientState::Failed; }, 5s));
  EXPECT_NE(ar.cm->module_diff().find("slot 1 (API 0x00003A00): wrong module (ident 0x00000101, expected 0x00000777)"),
            std::string_view::npos)
      << ar.cm->module_diff();
  EXPECT_EQ(l.akd->telegram(), 1);
}

TEST(PnSimAkd, Record47ReadsAPnuThroughTheParameterChannel) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0, 16, 5);  // watchdog 5 x 16 ms
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  // Read PNU 922 (the telegram) [digest §5.2, §11.1].
  std::array<std::uint8_t, 240> request{};
  const std::array<pd::ParamAddress, 1> what{{{pd::Attribute::Value, 1, 922, 0}}};
  const pd::EncodeResult e = pd::encode_read_request(request, 7, what);
  ASSERT_EQ(e.error, pd::ParamError::None);
  ASSERT_NE(ar.cm->submit_write(akd::kProfidriveApi, 1, 1, record_index::kAkdParameterAccess,
                                std::span<const std::uint8_t>(request).first(e.size)),
            0U);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.replies.count == 1; }, 5s));
  EXPECT_EQ(l.bench.replies.outcome, CmRecordOutcome::Done) << l.bench.replies.text;
  ASSERT_NE(ar.cm->submit_read(akd::kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, 240), 0U);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.replies.count == 2; }, 5s));
  ASSERT_EQ(l.bench.replies.outcome, CmRecordOutcome::Done) << l.bench.replies.text;
  const pd::ResponseResult r = pd::decode_param_response(l.bench.replies.data);
  ASSERT_EQ(r.error, pd::ParamError::None);
  EXPECT_EQ(r.response.reference, 7);
  ASSERT_EQ(r.response.values().size(), 1U);
  EXPECT_EQ(r.response.values()[0].value(0), 1U);
  // A second read with nothing waiting: PNIORW state conflict.
  ASSERT_NE(ar.cm->submit_read(akd::kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, 240), 0U);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.replies.count == 3; }, 5s));
  EXPECT_EQ(l.bench.replies.outcome, CmRecordOutcome::Refused);
  EXPECT_NE(l.bench.replies.text.find("state conflict"), std::string::npos) << l.bench.replies.text;
  // I&M0 of the DAP.
  ASSERT_NE(ar.cm->submit_read(0, 0, 1, record_index::kIm0, 64), 0U);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.replies.count == 4; }, 5s));
  const Im0View im = decode_im0(l.bench.replies.data);
  ASSERT_EQ(im.error, WireError::None);
  EXPECT_EQ(im.im0.order_id, "AKD-P00306-NBPN-0000");
  EXPECT_EQ(im.im0.profile_id, 0x3A00);
  // PN.TIMEOUTFTHRESH (PNU 3022) is the watchdog this AR assigned [digest §19.3].
  const std::array<pd::ParamAddress, 1> threshold{{{pd::Attribute::Value, 1, 3022, 0}}};
  const pd::EncodeResult e2 = pd::encode_read_request(request, 8, threshold);
  ASSERT_NE(ar.cm->submit_write(akd::kProfidriveApi, 1, 1, record_index::kAkdParameterAccess,
                                std::span<const std::uint8_t>(request).first(e2.size)),
            0U);
  ASSERT_NE(ar.cm->submit_read(akd::kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, 240), 0U);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.replies.count == 6; }, 5s));
  const pd::ResponseResult t = pd::decode_param_response(l.bench.replies.data);
  ASSERT_EQ(t.error, pd::ParamError::None);
  ASSERT_EQ(t.response.values().size(), 1U);
  EXPECT_EQ(t.response.values()[0].value(0), 80U);
}

TEST(PnSimAkd, SilentControllerMakesTheDeviceWatchdogAbortTheAr) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  put16(plan.provider->data(plan.index(1)), 0, 0x047E);
  l.bench.run_for(100ms);
  ASSERT_EQ(l.akd->drive().state(), pd::sim::State::S2ReadyForSwitchingOn);
  // The controller's output frames stop: after 3 x 16 ms the device ends the AR.
  plan.provider->stop();
  const core::TimePoint silent = l.bench.now;
  ASSERT_TRUE(l.bench.run_until([&] { return l.drive->ar_state() == CmServerState::NoAr; }, 1s));
  EXPECT_LE(l.bench.now - silent, 48ms + 16ms);
  EXPECT_EQ(l.drive->counters().watchdog_aborts, 1U);
  EXPECT_NE(l.drive->abort_reason().find("output CR watchdog: output frame 0xC002 silent"), std::string_view::npos)
      << l.drive->abort_reason();
  // The drive raises F702 (fieldbus communication lost, §18.3) and the input CR goes silent.
  l.bench.run_for(100ms);
  EXPECT_EQ(l.akd->drive().state(), pd::sim::State::Fault);
  const auto faults = l.akd->drive().fault_numbers();
  EXPECT_NE(std::find(faults.begin(), faults.end(), 702), faults.end());
  EXPECT_EQ(plan.consumer->state(), RtConsumerState::Timeout);
  // DCP Set works again without an AR.
  const DcpRequestId id = l.bench.dcp.set_ip(device_mac(1), suite(21), DcpQualifier::Temporary);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.dcp.result(id).status != DcpRequestStatus::InFlight &&
                                              l.bench.dcp.result(id).status != DcpRequestStatus::Queued; }, 5s));
  EXPECT_EQ(l.bench.dcp.result(id).status, DcpRequestStatus::Done);
}

TEST(PnSimAkd, DcpSetIsRefusedWhileTheArRuns) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  const DcpRequestId id = l.bench.dcp.set_ip(device_mac(1), suite(21), DcpQualifier::Temporary);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.dcp.result(id).status == DcpRequestStatus::Failed; }, 5s));
  EXPECT_EQ(l.bench.dcp.result(id).failure, DcpFailure::BlockError);
}

TEST(PnSimAkd, PowerLossEndsTheArAndTheDeviceComesBackWithoutTemporaryAddress) {
  Line l;
  // The device got its address temporarily (as the station finder assigns it).
  const DcpRequestId id = l.bench.dcp.set_ip(device_mac(1), suite(11), DcpQualifier::Temporary);
  ASSERT_TRUE(l.bench.run_until([&] { return l.bench.dcp.result(id).status == DcpRequestStatus::Done; }, 5s));
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  l.bench.run_for(100ms);
  l.drive->power_loss();
  ASSERT_TRUE(l.bench.run_until([&] { return plan.consumer->state() == RtConsumerState::Timeout; }, 1s));
  EXPECT_NE(plan.consumer->reason().find("input frame 0xC001 silent"), std::string_view::npos) << plan.consumer->reason();
  l.drive->power_return(l.bench.now);
  EXPECT_EQ(l.drive->ip(), 0U);
  EXPECT_EQ(l.drive->dcp().name_of_station(), "drive-a");  // the stored name stays
  EXPECT_EQ(l.drive->ar_state(), CmServerState::NoAr);
  EXPECT_EQ(l.akd->drive().state(), pd::sim::State::S1SwitchingOnInhibited);
  EXPECT_EQ(l.akd->drive().fault_counter(), 0);  // the drive model started over
}

TEST(PnSimAkd, DeviceAbortAndDriveFaultReachTheController) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  put16(plan.provider->data(plan.index(1)), 0, 0x047E);
  l.bench.run_for(100ms);
  l.akd->inject_drive_fault(501);
  l.bench.run_for(100ms);
  EXPECT_EQ(be16(plan.consumer->data(plan.index(1)), 0) & 0x0008, 0x0008);  // ZSW1 bit 3 fault
  l.drive->abort_ar("injected");
  EXPECT_EQ(l.drive->abort_reason(), "injected");
  ASSERT_TRUE(l.bench.run_until([&] { return plan.consumer->state() == RtConsumerState::Timeout; }, 1s));
}

TEST(PnSimAkd, LostOutputFramesWithinTheDataHoldTimeKeepTheAr) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  // Data hold factor 3: one lost frame is bridged (the next comes before 3 periods passed).
  l.drive->lose_rx_frames(1);
  l.drive->lose_tx_frames(1);
  l.bench.run_for(200ms);
  EXPECT_EQ(l.drive->counters().rx_lost, 1U);
  EXPECT_EQ(l.drive->counters().tx_lost, 1U);
  EXPECT_EQ(l.drive->ar_state(), CmServerState::DataExchange);
  EXPECT_EQ(plan.consumer->state(), RtConsumerState::Running);
  l.drive->lose_rx_frames(2);  // two: the third comes at the deadline, too late
  l.bench.run_for(200ms);
  EXPECT_EQ(l.drive->ar_state(), CmServerState::NoAr);
  EXPECT_EQ(l.drive->counters().watchdog_aborts, 1U);
}

TEST(PnSimGenericIo, ConnectsAndExchangesItsSubmodulesData) {
  Line l;
  ArPlan plan({{0, 0, 0x10, 1, 0x10, IoKind::NoIo, 0, 0},
               {0, 1, 0x20, 1, 0x21, IoKind::Input, 2, 0},
               {0, 2, 0x30, 1, 0x31, IoKind::Output, 0, 4}},
              ip_of(12), device_mac(2), 1, 8);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  const std::array<std::uint8_t, 2> in{0xAB, 0xCD};
  ASSERT_TRUE(l.io->set_input(0, 1, 1, in));
  const std::array<std::uint8_t, 4> out{1, 2, 3, 4};
  std::copy(out.begin(), out.end(), plan.provider->data(plan.index(2)).begin());
  l.bench.run_for(100ms);
  const auto got = plan.consumer->data(plan.index(1));
  EXPECT_EQ(Bytes(got.begin(), got.end()), Bytes(in.begin(), in.end()));
  const auto seen = l.io->output(0, 2, 1);
  EXPECT_EQ(Bytes(seen.begin(), seen.end()), Bytes(out.begin(), out.end()));
  EXPECT_EQ(l.io->outputs(0, 2, 1), PnOutputs::Valid);
  EXPECT_FALSE(l.io->set_input(0, 1, 1, out));  // wrong length
  // The AKD next to it is untouched.
  EXPECT_EQ(l.drive->ar_state(), CmServerState::NoAr);
}

TEST(PnSimAkd, TwoArsOnTwoDevicesAtOnce) {
  Line l;
  ArPlan drive(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  ArPlan io({{0, 0, 0x10, 1, 0x10, IoKind::NoIo, 0, 0}, {0, 1, 0x20, 1, 0x21, IoKind::Input, 2, 0}}, ip_of(12),
            device_mac(2), 1, 8);
  SimBench::Ar& a = l.bench.add_ar(drive);
  SimBench::Ar& b = l.bench.add_ar(io);
  l.bench.start(a);
  l.bench.start(b);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(a) && in_data_exchange(b); }, 5s))
      << a.cm->reason() << " / " << b.cm->reason();
  l.bench.run_for(100ms);
  EXPECT_EQ(drive.consumer->state(), RtConsumerState::Running);
  EXPECT_EQ(io.consumer->state(), RtConsumerState::Running);
  // Each controller consumer took its own device's frames (the other device's are another FrameID).
  EXPECT_GE(drive.consumer->counters().frames, 5U);
  EXPECT_GE(io.consumer->counters().frames, 10U);
  EXPECT_EQ(drive.consumer->counters().wrong_source + io.consumer->counters().wrong_source, 0U);
  const RtProvider* input = l.drive->input_cr();
  ASSERT_NE(input, nullptr);
  // The device's first frame may come before the controller armed its consumer (inactive).
  EXPECT_EQ(input->counters().frames_sent, drive.consumer->counters().frames + drive.consumer->counters().inactive);
}

TEST(PnSimAkd, DeviceCyclicPathDoesNotAllocate) {
  Line l;
  ArPlan plan(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  SimBench::Ar& ar = l.bench.add_ar(plan);
  l.bench.start(ar);
  ASSERT_TRUE(l.bench.run_until([&] { return in_data_exchange(ar); }, 5s)) << ar.cm->reason();
  put16(plan.provider->data(plan.index(1)), 0, 0x047E);
  // The controller's side of the AR's alarm CR, to acknowledge the device's alarms.
  AlarmChannel alarms(AlarmChannelConfig{kControllerMac, device_mac(1), plan.connect.alarm, kDeviceAlarmReference});
  alarms.open();
  AlarmNotification process;
  process.alarm_type = alarm_type::kProcess;
  process.api = akd::kProfidriveApi;
  process.slot = akd::kTelegramSlot;
  process.subslot = akd::kTelegramSubslot;
  // The device alone: its output frames fed in and its polls, 1000 cycles, an alarm every 50th
  // acknowledged by the controller's alarm CR.
  std::array<std::uint8_t, kMaxFrameSize> out_frame{};
  std::array<std::uint8_t, kMaxFrameSize> in_frame{};
  CmOutbox box;
  core::TimePoint t = l.bench.now;
  std::size_t sent = 0;
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 1000; ++i) {
    t += 16ms;
    if (i % 50 == 0) {
      ASSERT_TRUE(l.drive->send_alarm(process));
    }
    const std::size_t n = plan.provider->poll(t, out_frame);
    if (n > 0) (void)l.drive->on_frame(std::span<const std::uint8_t>(out_frame).first(n), t);
    for (bool any = true; any;) {
      any = false;
      while (const std::size_t m = l.drive->poll(t, in_frame, box)) {
        any = true;
        if (!alarms.on_frame(std::span<const std::uint8_t>(in_frame).first(m), t)) ++sent;  // an input CR frame
      }
      while (const std::size_t m = alarms.poll(t, out_frame)) {
        any = true;
        (void)l.drive->on_frame(std::span<const std::uint8_t>(out_frame).first(m), t);
      }
    }
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_GE(sent, 999U);
  EXPECT_EQ(l.drive->ar_state(), CmServerState::DataExchange);
  EXPECT_EQ(l.akd->drive().state(), pd::sim::State::S2ReadyForSwitchingOn);
  EXPECT_EQ(alarms.counters().alarms, 20U);
  ASSERT_NE(l.drive->alarm_cr(), nullptr);
  EXPECT_EQ(l.drive->alarm_cr()->counters().acknowledged, 20U);
}

}  // namespace
}  // namespace drivegate::profinet::test
