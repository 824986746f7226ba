// CmClient against CmServer on the in-memory network (cm_harness.hpp): the start-up of an AR from
// Connect to data exchange, record access, Release, and every way it can go wrong.
#include <gtest/gtest.h>

#include "tests/profinet_cm/cm_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet {
namespace {

using namespace test;

std::size_t count_type(const std::vector<Packet>& log, PacketType t, bool to_device) {
  std::size_t n = 0;
  for (const Packet& p : log) n += (p.type() == t && p.to_device() == to_device) ? 1U : 0U;
  return n;
}

TEST(PnCmClient, StartsUpWritesParametersAndReachesDataExchange) {
  Bench b;
  b.start();
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
  EXPECT_EQ(b.drive->state(), CmServerState::DataExchange);
  EXPECT_TRUE(b.plc->reason().empty());
  EXPECT_TRUE(b.plc->module_diff().empty());
  EXPECT_EQ(b.plc->input_frame_id(), 0xC001);
  EXPECT_EQ(b.plc->output_frame_id(), 0xC002);
  EXPECT_EQ(b.plc->ar_response().responder_mac, kDeviceMac);
  // The digest's PNU 930 write went to record 47 before PrmEnd.
  EXPECT_EQ(b.app.writes, 1);
  ASSERT_EQ(b.app.record47_size, kPnu930.size());
  EXPECT_TRUE(std::equal(kPnu930.begin(), kPnu930.end(), b.app.record47.begin()));
  // Connect, Write, PrmEnd, ApplicationReady: four requests, four responses, in this order.
  ASSERT_EQ(b.log.size(), 8U);
  const std::array<Opnum, 4> ops{Opnum::Connect, Opnum::Write, Opnum::Control, Opnum::Control};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(b.log[2 * i].type(), PacketType::Request) << i;
    EXPECT_EQ(b.log[2 * i].opnum(), ops[i]) << i;
    EXPECT_EQ(b.log[2 * i + 1].type(), PacketType::Response) << i;
  }
  // ApplicationReady: from the device's client port to the controller's RPC server port.
  EXPECT_EQ(b.log[6].to.port, kRpcUdpPort);
  EXPECT_EQ(b.log[6].to.ip, kPlcIp);
  EXPECT_EQ(b.log[6].header().interface, kPnioControllerInterface);
  EXPECT_EQ(b.log[7].to.port, kDriveClientPort);
  // Sequence numbers of the controller's activity count up.
  EXPECT_EQ(b.log[0].header().sequence_number, 0U);
  EXPECT_EQ(b.log[2].header().sequence_number, 1U);
  EXPECT_EQ(b.log[4].header().sequence_number, 2U);
  EXPECT_EQ(b.plc->counters().application_ready, 1U);
  EXPECT_EQ(b.plc->counters().rpc.retransmissions, 0U);
  EXPECT_EQ(b.plc->counters().rpc.malformed, 0U);
  EXPECT_EQ(b.drive->counters().rpc.malformed, 0U);

  // Record access in data exchange: I&M0, write and read back record 47, a refused write.
  const CmRecordId im0 = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  const std::array<std::uint8_t, 4> req{0x01, 0x01, 0x01, 0x01};
  const CmRecordId w = b.plc->submit_write(kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, req);
  const CmRecordId r = b.plc->submit_read(kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, 240);
  const CmRecordId denied = b.plc->submit_write(kProfidriveApi, 1, 1, kDeniedIndex, req);
  ASSERT_NE(im0, 0U);
  ASSERT_NE(denied, 0U);
  b.run_for(50ms);
  ASSERT_EQ(b.replies.replies.size(), 4U);
  const auto im = b.replies.find(im0);
  ASSERT_EQ(im.id, im0);
  EXPECT_EQ(im.outcome, CmRecordOutcome::Done);
  const Im0View iv = decode_im0(im.data);
  ASSERT_EQ(iv.error, WireError::None);
  EXPECT_EQ(iv.im0.order_id, "AKD-P00306-NBPN-0000");
  EXPECT_EQ(b.replies.find(w).outcome, CmRecordOutcome::Done);
  EXPECT_EQ(b.replies.find(r).data, std::vector<std::uint8_t>(req.begin(), req.end()));
  const auto d = b.replies.find(denied);
  EXPECT_EQ(d.outcome, CmRecordOutcome::Refused);
  EXPECT_EQ(d.status, (PnioStatus{0xDF, 0x80, 0xB6, 0x00}));
  EXPECT_NE(d.text.find("access denied"), std::string::npos) << d.text;
  EXPECT_NE(d.text.find("(DF 80 B6 00)"), std::string::npos) << d.text;
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange);

  b.plc->release(b.now, b.plc_out);
  b.shuttle();
  EXPECT_EQ(b.plc->state(), CmClientState::Released);
  EXPECT_EQ(b.drive->state(), CmServerState::NoAr);
  EXPECT_EQ(b.drive->counters().releases, 1U);
  EXPECT_EQ(b.log[b.log.size() - 2].opnum(), Opnum::Release);
}

TEST(PnCmClient, BigEndianDrepWorksToo) {
  Bench b(kDriveModel, ByteOrder::Big);
  b.start();
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
  EXPECT_EQ(b.log[0].header().order, ByteOrder::Big);
  EXPECT_EQ(b.log[1].header().order, ByteOrder::Big);
}

TEST(PnCmClient, WrongModuleIsReportedPerSlotAndRefused) {
  const std::array<CmModelSlot, 2> model{{{0, 0, kDapModule, kDapSubs}, {kProfidriveApi, 1, 0x00000102, kTelegramSubs}}};
  Bench b(model);
  b.start();
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_EQ(b.plc->failed_in(), CmClientState::Connecting);
  EXPECT_EQ(b.plc->module_diff(), "slot 1 (API 0x00003A00): wrong module (ident 0x00000102, expected 0x00000101)");
  EXPECT_EQ(b.plc->reason(),
            "Connecting: the device's modules differ from the expected ones: slot 1 (API 0x00003A00): wrong module "
            "(ident 0x00000102, expected 0x00000101)");
  // The AR existed on the device: released.
  EXPECT_EQ(b.drive->state(), CmServerState::NoAr);
  EXPECT_EQ(b.drive->counters().releases, 1U);
  EXPECT_EQ(b.app.writes, 0);
}

TEST(PnCmClient, MissingSlotAndWrongSubmoduleAreEachOneLine) {
  const std::array<CmModelSubmodule, 1> other_sub{{{1, 0x00000099}}};
  const std::array<CmModelSlot, 1> model{{{0, 0, kDapModule, other_sub}}};
  Bench b(model);
  b.start();
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_EQ(b.plc->module_diff(),
            "slot 0 subslot 1: wrong submodule (ident 0x00000099, expected 0x00000001)\n"
            "slot 1 (API 0x00003A00): no module");
}

TEST(PnCmClient, AcceptedModuleDiffRunsTheAr) {
  const std::array<CmModelSlot, 2> model{{{0, 0, kDapModule, kDapSubs}, {kProfidriveApi, 1, 0x00000102, kTelegramSubs}}};
  Bench b(model);
  b.config.accept_module_diff = true;
  b.rebuild_client();
  b.start();
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
  EXPECT_FALSE(b.plc->module_diff().empty());
}

TEST(PnCmClient, RefusedParameterWriteNamesTheStatusAndReleases) {
  Bench b;
  const std::array<std::uint8_t, 2> two{1, 2};
  const std::array<CmRecordWrite, 2> params{{{kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, kPnu930},
                                             {kProfidriveApi, 1, 1, kDeniedIndex, two}}};
  b.config.parameters = params;
  b.rebuild_client();
  b.start();
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_EQ(b.plc->failed_in(), CmClientState::Parameterising);
  EXPECT_EQ(b.plc->reason(),
            "Parameterising: write API 0x3A00 slot 1 subslot 1 index 4096 (0x1000) refused: IODWriteRes PNIORW: "
            "access: access denied (DF 80 B6 00)");
  EXPECT_EQ(b.drive->state(), CmServerState::NoAr);
  EXPECT_EQ(b.drive->counters().releases, 1U);
}

TEST(PnCmClient, ConnectRefusedByTheDeviceIsDecoded) {
  Bench b;
  b.start();
  ASSERT_EQ(b.drive->state(), CmServerState::DataExchange);
  // A second controller with another AR UUID: the simulated device has one AR.
  CmClientConfig other = b.config;
  other.activity.time_low ^= 1;
  other.connect.ar.ar_uuid.time_low ^= 1;
  CmClient second(other);
  second.start(b.now, b.plc_out);
  const CmDatagram& d = b.plc_out.front();
  b.drive->on_datagram(d.view(), {kPlcIp, 0xC003}, CmSocket::Server, b.now, b.drive_out);
  b.plc_out.pop();
  ASSERT_FALSE(b.drive_out.empty());
  second.on_datagram(b.drive_out.front().view(), {kDriveIp, kRpcUdpPort}, CmSocket::Client, b.now, b.plc_out);
  b.drive_out.pop();
  EXPECT_EQ(second.state(), CmClientState::Failed);
  EXPECT_EQ(second.reason(),
            "Connecting: Connect refused: IODConnectRes PNIO: CMRPC: Out of AR Resources (DB 81 40 04)");
  EXPECT_TRUE(b.plc_out.empty()) << "no Release after a refused Connect";
  EXPECT_EQ(b.drive->state(), CmServerState::DataExchange);
}

TEST(PnCmClient, OnlyRtClass1IsOffered) {
  Bench b;
  b.config.connect.output.properties = iocr_properties::kRtClass3;
  b.rebuild_client();
  EXPECT_FALSE(b.plc->start(b.now, b.plc_out));
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_NE(b.plc->reason().find("RT class 1"), std::string_view::npos);
  EXPECT_TRUE(b.plc_out.empty());
}

TEST(PnCmClient, LostDatagramsAreSentAgain) {
  Bench b;
  // Lose the first Connect request, the first PrmEnd response and the first ApplicationReady
  // response: each is recovered by a retransmission, answered from the cache where the call ran.
  int connects = 0, prm_end_responses = 0, ready_responses = 0;
  b.filter = [&](const Packet& p) {
    if (p.type() == PacketType::Request && p.opnum() == Opnum::Connect) return connects++ == 0 ? 0 : 1;
    if (p.type() == PacketType::Response && p.opnum() == Opnum::Control && !p.to_device()) {
      return prm_end_responses++ == 0 ? 0 : 1;
    }
    if (p.type() == PacketType::Response && p.opnum() == Opnum::Control && p.to_device()) {
      return ready_responses++ == 0 ? 0 : 1;
    }
    return 1;
  };
  b.start();
  b.run_for(5s);
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
  EXPECT_EQ(b.drive->state(), CmServerState::DataExchange);
  EXPECT_EQ(b.plc->counters().rpc.retransmissions, 2U);  // Connect, PrmEnd
  EXPECT_EQ(b.drive->counters().rpc.retransmissions, 1U);  // ApplicationReady
  EXPECT_EQ(b.drive->counters().rpc.duplicates_answered, 1U);  // PrmEnd from the cache
  EXPECT_EQ(b.plc->counters().rpc.duplicates_answered, 1U);  // ApplicationReady from the cache
  EXPECT_EQ(b.plc->counters().application_ready, 1U);
  EXPECT_EQ(b.drive->counters().connects, 1U);
}

TEST(PnCmClient, DuplicatedDatagramsAreIgnored) {
  Bench b;
  b.filter = [](const Packet&) { return 2; };
  b.start();
  b.run_for(3s);
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
  EXPECT_EQ(b.drive->state(), CmServerState::DataExchange);
  EXPECT_EQ(b.app.writes, 1) << "the parameter write ran once";
  EXPECT_EQ(b.drive->counters().connects, 1U);
  EXPECT_GT(b.plc->counters().rpc.stale, 0U);
  EXPECT_EQ(b.plc->counters().rpc.malformed, 0U);
  const CmRecordId r = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  b.run_for(100ms);
  EXPECT_EQ(b.replies.count_of(r), 1);
  EXPECT_EQ(b.app.reads, 1);
}

TEST(PnCmClient, SilentDeviceTimesOutWithTheReason) {
  Bench b;
  b.filter = [](const Packet& p) { return p.to_device() ? 0 : 1; };
  b.start();
  b.run_for(5s);
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_EQ(b.plc->reason(), "Connecting: Connect: no response from 192.168.0.2:34964 after 4 sends, 1000 ms apart");
  EXPECT_EQ(count_type(b.log, PacketType::Request, true), 4U);
  EXPECT_EQ(b.plc->counters().rpc.timeouts, 1U);
}

TEST(PnCmClient, MissingApplicationReadyFailsAndBothSidesGiveUp) {
  Bench b;
  b.config.application_ready_timeout = 2s;
  b.rebuild_client();
  b.filter = [](const Packet& p) { return p.type() == PacketType::Request && !p.to_device() ? 0 : 1; };
  b.start();
  EXPECT_EQ(b.plc->state(), CmClientState::WaitApplicationReady);
  b.run_for(5s);
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_EQ(b.plc->failed_in(), CmClientState::WaitApplicationReady);
  EXPECT_EQ(b.plc->reason(), "WaitApplicationReady: no ApplicationReady from the device within 2000 ms after PrmEnd");
  // The client released the AR; the device ended it either way.
  EXPECT_EQ(b.drive->state(), CmServerState::NoAr);
}

TEST(PnCmClient, DeviceGivesUpWhenApplicationReadyIsNotAnswered) {
  Bench b;
  b.filter = [](const Packet& p) { return p.type() == PacketType::Response && p.to_device() ? 0 : 1; };
  b.start();
  b.run_for(6s);
  EXPECT_EQ(b.drive->state(), CmServerState::NoAr);
  EXPECT_EQ(b.drive->abort_reason(), "Control: no response from 192.168.0.1:34964 after 4 sends, 1000 ms apart");
}

TEST(PnCmClient, LateResponseToAnEarlierSequenceIsIgnored) {
  Bench b;
  b.start();
  ASSERT_EQ(b.plc->state(), CmClientState::DataExchange);
  std::vector<Packet> held;
  b.filter = [&](const Packet& p) {
    if (p.type() == PacketType::Response && !p.to_device() && held.empty()) {
      held.push_back(p);
      return 0;
    }
    return 1;
  };
  const CmRecordId first = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  b.run_for(1500ms);  // the read is sent again and answered from the device's cache
  ASSERT_EQ(b.replies.count_of(first), 1);
  const CmRecordId second = b.plc->submit_read(kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, 240);
  ASSERT_EQ(held.size(), 1U);
  // The first read's response arrives late, while the second read runs: dropped as stale.
  const std::uint64_t stale = b.plc->counters().rpc.stale;
  b.deliver(held[0].from, held[0].to, held[0].bytes);
  EXPECT_EQ(b.plc->counters().rpc.stale, stale + 1);
  b.run_for(100ms);
  EXPECT_EQ(b.replies.count_of(first), 1);
  EXPECT_EQ(b.replies.count_of(second), 1);
  EXPECT_EQ(b.replies.find(second).outcome, CmRecordOutcome::Done);
  EXPECT_EQ(b.app.reads, 2);
}

TEST(PnCmClient, WorkingThenPingThenNocallSendsTheRequestAgain) {
  Bench b;
  b.plc->start(b.now, b.plc_out);
  ASSERT_EQ(b.plc_out.size(), 1U);
  std::vector<std::uint8_t> connect(b.plc_out.front().view().begin(), b.plc_out.front().view().end());
  b.plc_out.pop();
  const RpcHeader req = decode_rpc(connect).header;
  auto answer = [&](PacketType t) {
    RpcHeader h = response_header_for(req, 1);
    h.packet_type = static_cast<std::uint8_t>(t);
    std::array<std::uint8_t, kRpcHeaderSize> bytes{};
    ASSERT_EQ(encode_rpc_header(h, bytes), kRpcHeaderSize);
    b.plc->on_datagram(bytes, {kDriveIp, kRpcUdpPort}, CmSocket::Client, b.now, b.plc_out);
  };
  answer(PacketType::Working);
  EXPECT_TRUE(b.plc_out.empty());
  b.now += 1s;
  b.plc->poll(b.now, b.plc_out);
  ASSERT_EQ(b.plc_out.size(), 1U);
  const RpcHeader ping = decode_rpc(b.plc_out.front().view()).header;
  EXPECT_EQ(ping.packet_type, static_cast<std::uint8_t>(PacketType::Ping));
  EXPECT_EQ(ping.sequence_number, req.sequence_number);
  EXPECT_EQ(ping.activity, req.activity);
  b.plc_out.pop();
  answer(PacketType::Nocall);
  ASSERT_EQ(b.plc_out.size(), 1U);
  EXPECT_TRUE(std::equal(connect.begin(), connect.end(), b.plc_out.front().view().begin()));
  b.shuttle();
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange) << b.plc->reason();
  EXPECT_EQ(b.plc->counters().rpc.working, 1U);
  EXPECT_EQ(b.plc->counters().rpc.pings, 1U);
  EXPECT_EQ(b.plc->counters().rpc.nocalls, 1U);
}

TEST(PnCmClient, FragmentedResponseIsRefusedWithAClearError) {
  Bench b;
  b.filter = [](const Packet&) { return 0; };
  b.start();
  // The device's real answer, with the fragment flag set.
  b.filter = nullptr;
  b.deliver(b.log[0].from, b.log[0].to, b.log[0].bytes);
  ASSERT_FALSE(b.drive_out.empty());
  std::vector<std::uint8_t> res(b.drive_out.front().view().begin(), b.drive_out.front().view().end());
  b.drive_out.pop();
  res[2] |= rpc_flag1::kFragment;
  b.plc->on_datagram(res, {kDriveIp, kRpcUdpPort}, CmSocket::Client, b.now, b.plc_out);
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_EQ(b.plc->reason(),
            "Connecting: Connect: the peer answered with a fragmented response (fragment 0): RPC fragmentation is not "
            "supported");
}

TEST(PnCmClient, MalformedDatagramsAreCountedAndDropped) {
  Bench b;
  b.start();
  ASSERT_EQ(b.plc->state(), CmClientState::DataExchange);
  std::vector<std::uint8_t> good = b.log[1].bytes;  // the Connect response
  std::vector<std::vector<std::uint8_t>> bad{
      {},                                                        // empty
      std::vector<std::uint8_t>(good.begin(), good.begin() + 40),  // truncated header
      good,                                                      // wrong RPC version, below
      good,                                                      // fragment length beyond the data
  };
  bad[2][0] = 5;
  bad[3][74] = 0xFF;
  bad[3][75] = 0xFF;
  for (const auto& d : bad) {
    b.plc->on_datagram(d, {kDriveIp, kRpcUdpPort}, CmSocket::Client, b.now, b.plc_out);
    b.plc->on_datagram(d, {kDriveIp, kDriveClientPort}, CmSocket::Server, b.now, b.plc_out);
    b.drive->on_datagram(d, {kPlcIp, kPlcClientPort}, CmSocket::Server, b.now, b.drive_out);
  }
  EXPECT_EQ(b.plc->counters().rpc.malformed, 8U);
  EXPECT_EQ(b.drive->counters().rpc.malformed, 4U);
  EXPECT_TRUE(b.plc_out.empty());
  EXPECT_TRUE(b.drive_out.empty());
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange);
  EXPECT_EQ(b.drive->state(), CmServerState::DataExchange);
}

TEST(PnCmClient, RecordQueueGivesExactlyOneReplyEach) {
  Bench b;
  b.start();
  ASSERT_EQ(b.plc->state(), CmClientState::DataExchange);
  std::array<CmRecordId, CmClient::kRecordQueueDepth> ids{};
  for (auto& id : ids) {
    id = b.plc->submit_read(0, 0, 1, record_index::kIm0);
    ASSERT_NE(id, 0U);
  }
  EXPECT_EQ(b.plc->submit_read(0, 0, 1, record_index::kIm0), 0U) << "queue full";
  EXPECT_EQ(b.plc->counters().queue_full, 1U);
  std::array<std::uint8_t, CmClient::kMaxRecordData + 1> too_long{};
  EXPECT_EQ(b.plc->submit_write(0, 0, 1, 0x1000, too_long), 0U);
  // An invalid slot is refused by the device with PNIORW.
  b.run_for(50ms);
  const CmRecordId bad_slot = b.plc->submit_read(0, 7, 1, record_index::kIm0);
  b.run_for(50ms);
  for (const CmRecordId id : ids) EXPECT_EQ(b.replies.count_of(id), 1);
  const auto r = b.replies.find(bad_slot);
  ASSERT_EQ(r.id, bad_slot);
  EXPECT_EQ(r.outcome, CmRecordOutcome::Refused);
  EXPECT_NE(r.text.find("invalid slot"), std::string::npos) << r.text;

  // A silent device: the record fails with the timeout; the ones behind it are aborted by Release.
  b.filter = [](const Packet& p) { return p.to_device() ? 0 : 1; };
  const CmRecordId lost = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  b.run_for(4500ms);
  ASSERT_EQ(b.replies.count_of(lost), 1);
  EXPECT_EQ(b.replies.find(lost).outcome, CmRecordOutcome::Failed);
  EXPECT_EQ(b.replies.find(lost).text, "Read: no response from 192.168.0.2:34964 after 4 sends, 1000 ms apart");
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange);
  const CmRecordId queued1 = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  const CmRecordId queued2 = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  b.poll();
  b.plc->release(b.now, b.plc_out);
  EXPECT_EQ(b.replies.count_of(queued1), 1);
  EXPECT_EQ(b.replies.count_of(queued2), 1);
  EXPECT_EQ(b.replies.find(queued2).outcome, CmRecordOutcome::Aborted);
  EXPECT_EQ(b.plc->submit_read(0, 0, 1, record_index::kIm0), 0U) << "no records once released";
  b.run_for(5s);
  EXPECT_EQ(b.plc->state(), CmClientState::Failed);
  EXPECT_EQ(b.plc->failed_in(), CmClientState::Releasing);
  EXPECT_EQ(b.replies.count_of(queued1), 1);
}

TEST(PnCmClient, RecordsWaitForDataExchange) {
  Bench b;
  b.filter = [](const Packet& p) { return p.type() == PacketType::Request && !p.to_device() ? 0 : 1; };
  b.start();
  ASSERT_EQ(b.plc->state(), CmClientState::WaitApplicationReady);
  const CmRecordId r = b.plc->submit_read(0, 0, 1, record_index::kIm0);
  ASSERT_NE(r, 0U);
  b.run_for(100ms);
  EXPECT_EQ(b.replies.count_of(r), 0);
  b.filter = nullptr;
  b.run_for(1100ms);  // the device sends ApplicationReady again
  EXPECT_EQ(b.plc->state(), CmClientState::DataExchange);
  b.run_for(20ms);
  EXPECT_EQ(b.replies.count_of(r), 1);
  EXPECT_EQ(b.replies.find(r).outcome, CmRecordOutcome::Done);
}

TEST(PnCmClient, RecordAccessAllocatesNothing) {
  Bench b;
  b.start();
  ASSERT_EQ(b.plc->state(), CmClientState::DataExchange);
  b.capture = false;
  b.replies.keep = false;
  const std::array<std::uint8_t, 14> data = kPnu930;
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    b.plc->submit_write(kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, data);
    b.plc->submit_read(kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, 240);
    b.plc->submit_read(0, 0, 1, record_index::kIm0);
    b.now += 1ms;
    b.poll();
    b.now += 1ms;
    b.poll();
    b.now += 1ms;
    b.poll();
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(b.replies.count, 300);
  EXPECT_EQ(b.plc->counters().records_done, 300U);
}

}  // namespace
}  // namespace drivegate::profinet
