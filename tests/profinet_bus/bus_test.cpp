// The PROFINET bus on simulated devices: stations found by name and given their IP, ARs to data
// exchange, an AKD enabled and run in speed mode through its telegram, another moved in MDI and
// disabled, a jog quick-stopped at the soft limits, a PNU read over record 47, the IO device's
// bytes both ways, losses (power, AR abort) that reconnect only the device that was lost with a new
// AR and its axis disabled, a missing station and a wrong module named, the ARs released on close,
// no allocation per cycle in data exchange, a drive fault read from the fault buffer over record 47
// and acknowledged, and alarms as events.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "core/device_identity.hpp"
#include "tests/profinet_bus/bus_harness.hpp"
#include "tests/support/alloc_counter.hpp"
#include "tests/support/param_request.hpp"

namespace drivegate::profinet::test {
namespace {

std::string replaced(std::string s, const std::string& what, const std::string& with) {
  const auto at = s.find(what);
  if (at == std::string::npos) throw std::runtime_error("no " + what);
  return s.replace(at, what.size(), with);
}

core::CommandId set_mode(PnHarness& h, const std::string& name, core::Mode m) {
  core::Command c;
  c.id = h.next_id++;
  c.axis = h.axis(name);
  c.kind = core::CommandKind::SetMode;
  c.mode = m;
  EXPECT_TRUE(h.runner->push_command(c));
  return c.id;
}

TEST(ProfinetBus, FindsNamesConnectsAndExchangesData) {
  PnHarness h;
  EXPECT_EQ(h.link("x"), core::LinkState::Booting);  // searching
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  // Every device got its configured address by DCP (they came up without one) and one AR.
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(h.bus->ars(k), 1U);
    EXPECT_EQ(h.bus->cm(k)->state(), CmClientState::DataExchange);
  }
  EXPECT_NE(h.bus->device_detail(0).find("station \"akd-x\" (02:1b:1b:00:0a:01 at 192.168.0.10): in data exchange (AR 1)"),
            std::string_view::npos)
      << h.details();
  // I&M0 of the DAP, read once data exchange started, in the detail.
  ASSERT_TRUE(h.run_until([&] { return !h.bus->identity(0).empty(); }, 1s));
  EXPECT_EQ(h.bus->identity(0), "I&M0 order AKD-P00306-NBPN-0000 serial SIM0000001 hw 0 sw V0.0.0") << h.details();
  EXPECT_NE(h.bus->device_detail(0).find("in data exchange (AR 1); I&M0 order AKD-P00306-NBPN-0000"), std::string_view::npos);
  EXPECT_EQ(h.bus->identity(2).substr(0, 15), "I&M0 order IO-1");
  // Clients read it back from the axis' link detail (drivegatectl list).
  const auto id = core::identity_in_link_detail(h.bus->link_detail(h.axis("x")));
  ASSERT_TRUE(id) << h.details();
  EXPECT_EQ(id->order_id, "AKD-P00306-NBPN-0000");
  EXPECT_EQ(id->serial_number, "SIM0000001");
  EXPECT_EQ(id->hardware_revision, "0");
  EXPECT_EQ(id->software_revision, "V0.0.0");
  EXPECT_EQ(h.sim->akd_x->telegram(), 1);
  EXPECT_EQ(h.sim->akd_y->telegram(), 9);
  // The drives come up disabled: S1 (switching on inhibited).
  EXPECT_EQ(h.snap("x").state, core::AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.snap("y").state, core::AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.snap("x").link, core::LinkState::Operational);
  const core::BusCounters c = h.bus->counters();
  EXPECT_GT(c.frames_sent, 0U);
  EXPECT_GT(c.frames_received, 0U);
  EXPECT_EQ(c.errors, 0U);
}

TEST(ProfinetBus, EnablesAnAkdAndRunsItInSpeedMode) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  const auto en = h.push("x", core::CommandKind::Enable);
  ASSERT_EQ(h.wait_final(en, 3s), core::ReplyStatus::Completed) << h.reason(en);
  EXPECT_EQ(h.snap("x").state, core::AxisState::OperationEnabled);
  EXPECT_EQ(h.sim->akd_x->drive().state(), profidrive::sim::State::S4Operation);
  ASSERT_EQ(h.wait_final(set_mode(h, "x", core::Mode::ProfileVelocity), 1s), core::ReplyStatus::Completed);
  const auto v = h.push("x", core::CommandKind::Velocity, 0, 5.0);  // 5 rev/s
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("x").velocity - 5.0) < 0.1; }, 3s))
      << h.snap("x").velocity << " " << h.reason(v);
  // The other drive was not touched.
  EXPECT_EQ(h.snap("y").state, core::AxisState::SwitchOnDisabled);
  const auto off = h.push("x", core::CommandKind::Disable);
  ASSERT_EQ(h.wait_final(off, 5s), core::ReplyStatus::Completed) << h.reason(off);
}

core::Command motion(PnHarness& h, const std::string& name, core::CommandKind kind, double position, double velocity) {
  core::Command c;
  c.id = h.next_id++;
  c.axis = h.axis(name);
  c.kind = kind;
  c.position = position;  // rev
  c.velocity = velocity;  // rev/s
  c.acceleration = 20.0;
  c.deceleration = 20.0;
  EXPECT_TRUE(h.runner->push_command(c));
  return c;
}

// Telegram 9 at the AKD's 16 ms update: homed, moved out and back in MDI, each move landing on
// its target; jogged (real-time jog), its speed shown although telegram 9 carries no NIST_A (the
// slope of XIST_A); then disabled: OFF1 from standstill and on to S1.
TEST(ProfinetBus, MdiMovesLandOnTheirTargetsAJogShowsItsSpeedAndTheDriveDisables) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_EQ(h.wait_final(h.push("y", core::CommandKind::Enable), 3s), core::ReplyStatus::Completed);
  const auto home = h.push("y", core::CommandKind::Home);
  ASSERT_EQ(h.wait_final(home, 10s), core::ReplyStatus::Completed) << h.reason(home);
  for (const double target : {3.0, 0.0}) {
    const auto mv = motion(h, "y", core::CommandKind::Move, target, 2.0).id;
    ASSERT_EQ(h.wait_final(mv, 10s), core::ReplyStatus::Completed)
        << h.reason(mv) << ": at " << h.snap("y").position << " rev, " << h.snap("y").velocity << " rev/s";
    EXPECT_NEAR(h.snap("y").position, target, 1e-3);
  }
  const auto jog = motion(h, "y", core::CommandKind::Velocity, 0, -1.5);
  core::Setpoint alive;  // a jog lasts while its set-point is kept alive (the command timeout)
  alive.axis = jog.axis;
  alive.velocity = jog.velocity;
  bool jogging = false;
  for (int i = 0; i < 100 && !jogging; ++i) {
    ASSERT_TRUE(h.runner->push_setpoint(alive));
    jogging = h.run_until([&] { return std::fabs(h.snap("y").velocity + 1.5) < 0.01; }, 50ms);
  }
  ASSERT_TRUE(jogging) << h.snap("y").velocity << " rev/s; the drive at " << h.sim->akd_y->drive().velocity_rps();
  EXPECT_LT(h.snap("y").position, 0.0);
  const auto off = h.push("y", core::CommandKind::Disable);
  ASSERT_EQ(h.wait_final(off, 5s), core::ReplyStatus::Completed) << h.reason(off) << h.events_text();
  EXPECT_EQ(h.snap("y").state, core::AxisState::SwitchOnDisabled);
  EXPECT_NEAR(h.snap("y").velocity, 0.0, 0.05);
  EXPECT_EQ(h.sim->akd_y->drive().state(), profidrive::sim::State::S1SwitchingOnInhibited);
}

// The soft limits hold for a jog too: telegram 9 carries no NIST_A, and the velocity the limit
// watch judges "moving out" by is XIST_A's slope (it read 0, and a jog ran through the limit).
TEST(ProfinetBus, AJogThatLeavesTheSoftLimitsIsQuickStopped) {
  PnHarness h(replaced(kNetwork, "profinet: { station: akd-y, telegram: 9 } }",
                       "profinet: { station: akd-y, telegram: 9 }, limits: { min_position: -0.5, max_position: 0.5 } }"));
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_EQ(h.wait_final(h.push("y", core::CommandKind::Enable), 3s), core::ReplyStatus::Completed);
  ASSERT_EQ(h.wait_final(h.push("y", core::CommandKind::Home), 10s), core::ReplyStatus::Completed);
  const auto jog = motion(h, "y", core::CommandKind::Velocity, 0, -1.5);
  core::Setpoint alive;
  alive.axis = jog.axis;
  alive.velocity = jog.velocity;
  bool stopped = false;
  for (int i = 0; i < 100 && !stopped; ++i) {
    ASSERT_TRUE(h.runner->push_setpoint(alive));
    stopped = h.run_until([&] { return h.snap("y").state != core::AxisState::OperationEnabled; }, 50ms);
  }
  ASSERT_TRUE(stopped) << h.snap("y").position << " rev" << h.events_text();
  EXPECT_NE(h.events_text().find("outside the soft limits [-0.5, 0.5] rev and moving out: quick stop"), std::string::npos)
      << h.events_text();
  EXPECT_GT(h.snap("y").position, -1.0);  // caught within the quick stop's distance
  EXPECT_EQ(h.wait_final(jog.id, 1s), core::ReplyStatus::Failed);
}

TEST(ProfinetBus, ReadsAPnuOverRecord47) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  // PNU 922: the telegram the drive runs [digest §11.1].
  core::ParamRequest r = drivegate::test::param_read(h.next_id++, 922, 0, core::ParamType::U16);
  r.axis = h.axis("y");
  ASSERT_TRUE(h.runner->push_parameter(r));
  core::ParamReply reply;
  ASSERT_TRUE(h.run_until([&] { return h.runner->pop_parameter_reply(reply); }, 3s));
  ASSERT_TRUE(reply.ok) << reply.error.view();
  EXPECT_EQ(drivegate::test::reply_integer(reply), 9);
}

TEST(ProfinetBus, IoDeviceBytesGoBothWays) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_EQ(h.bus->io_count(), 1U);
  const core::IoInfo info = h.bus->io_info(0);
  EXPECT_EQ(info.name, "panel");
  EXPECT_EQ(info.input_size, 2U);
  EXPECT_EQ(info.output_size, 4U);
  const std::array<std::uint8_t, 2> in{0x12, 0x34};
  ASSERT_TRUE(h.sim->io->set_input(0, 1, 1, in));
  core::IoSnapshot s;
  ASSERT_TRUE(h.run_until([&] {
    h.bus->io_read(0, s);
    return s.valid && s.input_size == 2 && s.inputs[0] == 0x12 && s.inputs[1] == 0x34;
  }, 1s));
  const std::array<std::uint8_t, 4> out{1, 2, 3, 4};
  EXPECT_EQ(h.bus->io_write(0, 0, out), core::IoWriteStatus::Ok);
  EXPECT_EQ(h.bus->io_write(0, 3, std::span<const std::uint8_t>(out).first(2)), core::IoWriteStatus::OutOfRange);
  EXPECT_EQ(h.bus->io_write(1, 0, out), core::IoWriteStatus::UnknownSlave);
  ASSERT_TRUE(h.run_until([&] {
    const auto o = h.sim->io->output(0, 2, 1);
    return o.size() == 4 && o[0] == 1 && o[3] == 4;
  }, 1s));
  h.bus->io_read(0, s);
  EXPECT_EQ(s.output_size, 4U);
  EXPECT_EQ(s.outputs[2], 3);
}

TEST(ProfinetBus, PowerLossOfOneDriveReconnectsItWithANewArAndLeavesTheOthers) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  const auto en = h.push("x", core::CommandKind::Enable);
  ASSERT_EQ(h.wait_final(en, 3s), core::ReplyStatus::Completed) << h.reason(en);
  h.sim->x->power_loss();
  // The input CR's watchdog: 3 x 16 ms.
  ASSERT_TRUE(h.run_until([&] { return h.link("x") == core::LinkState::Lost; }, 200ms)) << h.details();
  EXPECT_NE(h.bus->device_detail(0).find("lost: input frame"), std::string_view::npos) << h.details();
  EXPECT_EQ(h.link("y"), core::LinkState::Operational);
  h.run_for(500ms);
  h.sim->x->power_return(h.now);
  ASSERT_TRUE(h.run_until([&] { return h.up("x"); }, 10s)) << h.details();
  EXPECT_EQ(h.bus->ars(0), 2U);
  EXPECT_EQ(h.bus->ars(1), 1U);  // y kept its AR throughout
  EXPECT_EQ(h.bus->ars(2), 1U);
  // The axis comes back disabled; the drive lost its temporary IP and got it again.
  EXPECT_EQ(h.snap("x").state, core::AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.sim->akd_x->drive().state(), profidrive::sim::State::S1SwitchingOnInhibited);
}

TEST(ProfinetBus, DeviceAbortingItsArIsLostAndReconnected) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.sim->block->abort_ar("test abort");
  ASSERT_TRUE(h.run_until([&] { return h.bus->phase(2) == ProfinetBus::Phase::Wait; }, 500ms)) << h.details();
  ASSERT_TRUE(h.run_until([&] { return h.bus->phase(2) == ProfinetBus::Phase::Running; }, 10s)) << h.details();
  EXPECT_EQ(h.bus->ars(2), 2U);
  EXPECT_EQ(h.bus->ars(0), 1U);
  core::IoSnapshot s;
  EXPECT_TRUE(h.run_until([&] {
    h.bus->io_read(0, s);
    return s.valid;
  }, 200ms));
}

TEST(ProfinetBus, MissingStationIsNamedAndTheOthersRun) {
  const std::string yaml = replaced(
      replaced(kNetwork, "      - { station: io-block,", "      - { station: akd-z, ip: 192.168.0.12 }\n      - { station: io-block,"),
      "axes:\n", "axes:\n  - { name: z, bus: pn0, address: 3, device: kollmorgen-akd-profinet, profinet: { station: akd-z, telegram: 1 } }\n");
  PnHarness h(yaml);
  ASSERT_TRUE(h.run_until([&] { return h.up("x") && h.up("y"); }, 5s)) << h.details();
  // dcp_timeout (3 s) of asking again, then the report.
  ASSERT_TRUE(h.run_until([&] { return h.bus->phase(2) == ProfinetBus::Phase::Wait; }, 5s)) << h.details();
  EXPECT_EQ(h.bus->device_detail(2), "station \"akd-z\": no device answers to this name (DCP Identify)");
  EXPECT_EQ(h.link("z"), core::LinkState::Offline);
  EXPECT_EQ(h.snap("z").link_detail.view(), h.bus->device_detail(2));
}

TEST(ProfinetBus, WrongModuleIsReportedPerSlot) {
  PnHarness h(replaced(kNetwork, "module_ident: 0x30,", "module_ident: 0x33,"));
  ASSERT_TRUE(h.run_until([&] { return h.bus->phase(2) == ProfinetBus::Phase::Wait; }, 5s)) << h.details();
  EXPECT_NE(h.bus->device_detail(2).find("failed: Connecting: the device's modules differ from the expected ones: slot 2: wrong module (ident "
                                                   "0x00000030, expected 0x00000033)"),
            std::string_view::npos)
      << h.details();
  EXPECT_TRUE(h.run_until([&] { return h.up("x") && h.up("y"); }, 5s)) << h.details();
}

TEST(ProfinetBus, CloseReleasesEveryAr) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.bus->close();
  EXPECT_EQ(h.sim->x->ar_state(), CmServerState::NoAr);
  EXPECT_EQ(h.sim->y->ar_state(), CmServerState::NoAr);
  EXPECT_EQ(h.sim->block->ar_state(), CmServerState::NoAr);
  EXPECT_EQ(h.bus->cm(0)->state(), CmClientState::Released);
}

TEST(ProfinetBus, NoAllocationPerCycleInDataExchange) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  const auto en = h.push("x", core::CommandKind::Enable);
  ASSERT_EQ(h.wait_final(en, 3s), core::ReplyStatus::Completed) << h.reason(en);
  ASSERT_EQ(h.wait_final(set_mode(h, "x", core::Mode::ProfileVelocity), 1s), core::ReplyStatus::Completed);
  (void)h.push("x", core::CommandKind::Velocity, 0, 2.0);
  h.run_for(100ms);
  const std::array<std::uint8_t, 4> out{5, 6, 7, 8};
  core::IoSnapshot s;
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 2000; ++i) {
    h.now += 1ms;
    h.runner->cycle(h.now);
    h.bus->io_read(0, s);
    (void)h.bus->io_write(0, 0, out);
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_TRUE(h.all_up()) << h.details();
}

}  // namespace
}  // namespace drivegate::profinet::test

namespace drivegate::profinet::test {
namespace {

TEST(ProfinetBus, DriveFaultIsReadFromTheFaultBufferAndAcknowledged) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  const auto en = h.push("x", core::CommandKind::Enable);
  ASSERT_EQ(h.wait_final(en, 3s), core::ReplyStatus::Completed) << h.reason(en);
  h.sim->akd_x->inject_drive_fault(235);  // heat sink temperature too high
  ASSERT_TRUE(h.run_until([&] { return h.snap("x").state == core::AxisState::Fault; }, 1s));
  // The fault buffer (PNU 944 -> 947 -> 944 over record 47) names it with the profile's text.
  ASSERT_TRUE(h.run_until([&] { return h.events_text().find("Heat sink temperature too high") != std::string::npos; }, 3s))
      << h.events_text();
  EXPECT_EQ(h.snap("y").state, core::AxisState::SwitchOnDisabled);
  const auto reset = h.push("x", core::CommandKind::FaultReset);
  ASSERT_EQ(h.wait_final(reset, 3s), core::ReplyStatus::Completed) << h.reason(reset);
  EXPECT_EQ(h.snap("x").state, core::AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.bus->ars(0), 1U);
}

}  // namespace
}  // namespace drivegate::profinet::test

namespace drivegate::profinet::test {
namespace {

TEST(ProfinetBus, AlarmsBecomeEventsOfTheDevicesAxesOrOfTheBus) {
  PnHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  AlarmNotification n;
  n.priority = AlarmPriority::Low;
  n.alarm_type = alarm_type::kPull;
  n.api = 0x3A00;
  n.slot = 1;
  n.subslot = 1;
  ASSERT_TRUE(h.sim->x->send_alarm(n));
  ASSERT_TRUE(h.run_until([&] { return h.events_text().find("Pull") != std::string::npos; }, 1s)) << h.events_text();
  bool on_x = false;
  for (const auto& e : h.events)
    if (e.kind == core::EventKind::Warning && e.axis == h.axis("x") && e.text.view().find("Pull") != std::string_view::npos)
      on_x = true;
  EXPECT_TRUE(on_x) << h.events_text();
  // The IO device's alarm is the bus'.
  n.alarm_type = alarm_type::kProcess;
  n.priority = AlarmPriority::High;
  n.api = 0;
  ASSERT_TRUE(h.sim->block->send_alarm(n));
  ASSERT_TRUE(h.run_until([&] { return h.events_text().find("station io-block: alarm high: Process") != std::string::npos; }, 1s))
      << h.events_text();
  // Acknowledged: the ARs run on.
  h.run_for(500ms);
  EXPECT_TRUE(h.all_up()) << h.details();
  EXPECT_EQ(h.bus->alarms(0)->counters().alarms, 1U);
  EXPECT_EQ(h.bus->ars(0), 1U);
}

}  // namespace
}  // namespace drivegate::profinet::test
