// The EtherCAT bus on a simulated line: start-up to OP, the axes disabled; first smoke test.
#include <gtest/gtest.h>

#include "tests/ethercat_bus/bus_harness.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::LinkState;
using core::ReplyStatus;

TEST(EthercatBus, ReachesOpWithTheAxesDisabled) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  std::printf("up after %lld ms of bus time\n", static_cast<long long>(core::to_ns(h.now) / 1000000));
  EXPECT_EQ(h.esr.esc->state(), AlState::Op);
  EXPECT_EQ(h.panel_esc->state(), AlState::Op);
  EXPECT_EQ(h.gen.esc->state(), AlState::Op);
  EXPECT_EQ(h.snap("esr").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.snap("gen").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.bus->link_detail(h.axis("esr")), "slave 1 (0x1001, ESR TrioDrive D/ES): in OP");
}

// `transport: sim` as the daemon builds it: the line made from the profiles' personas (the ESR,
// the `io:` panel, the generic drive) comes up, and a drive enables.
TEST(EthercatBus, TransportSimMakesTheLineFromTheProfiles) {
  EcatHarness h(kLine, false);
  h.make_from_factory();
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->link_detail(h.axis("esr")), "slave 1 (0x1001, ESR TrioDrive D/ES): in OP");
  EXPECT_EQ(h.snap("gen").state, AxisState::SwitchOnDisabled);
  const auto id = h.push("gen", CommandKind::Enable);
  ASSERT_EQ(h.wait_final(id, 3s), ReplyStatus::Completed) << h.reason(id) << h.events_text();
  EXPECT_EQ(h.snap("gen").state, AxisState::OperationEnabled);
}

}  // namespace
}  // namespace drivegate::ethercat::test

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::LinkState;
using core::Mode;
using core::ReplyStatus;

void expect_completed(EcatHarness& h, core::CommandId id, core::Duration budget, const std::string& what) {
  ASSERT_EQ(h.wait_final(id, budget), ReplyStatus::Completed) << what << ": " << h.reason(id) << h.events_text()
                                                              << h.details();
}

void up(EcatHarness& h) { ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text(); }

// ip on the ESR: 60C1h:01 every cycle with interpolation enabled (dunker-ethercat-coe.md §12).
TEST(EthercatBusModes, EsrEnablesAndFollowsIpSetpoints) {
  EcatHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("esr", CommandKind::Enable), 3s, "enable");
  EXPECT_EQ(h.snap("esr").state, AxisState::OperationEnabled);
  expect_completed(h, h.set_mode("esr", Mode::InterpolatedPosition), 3s, "ip");
  double target = h.snap("esr").position;
  const double start = target;
  for (int i = 0; i < 300; ++i) {
    target += 0.002;
    core::Setpoint sp;
    sp.axis = h.axis("esr");
    sp.position = target;
    ASSERT_TRUE(h.runner->push_setpoint(sp));
    h.cycle();
  }
  h.run_until([] { return false; }, 50ms);
  EXPECT_NEAR(h.snap("esr").position, target, 0.05) << "from " << start;
  EXPECT_NE(h.esr.app->drive().read_object({0x60C1, 1}).value, 0);
  expect_completed(h, h.push("esr", CommandKind::Disable), 3s, "disable");
}

// pp on the ESR: an absolute move sets controlword bit 6 there (quirk pp_bit6_absolute,
// dunker-ethercat-coe.md §14 item 14), so the same absolute target twice ends where it was asked to,
// not twice as far.
TEST(EthercatBusModes, EsrAbsoluteMovesLandOnTheirTarget) {
  EcatHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("esr", CommandKind::Enable), 3s, "enable");
  expect_completed(h, h.set_mode("esr", Mode::ProfilePosition), 3s, "pp");
  const double start = h.snap("esr").position;
  const double target = start + 0.5;
  for (int i = 0; i < 2; ++i) {
    expect_completed(h, h.push("esr", CommandKind::Move, target, 5), 5s, "move");
    EXPECT_NEAR(h.snap("esr").position, target, 0.01) << "move " << i << " from " << start;
  }
  expect_completed(h, h.push("esr", CommandKind::Disable), 3s, "disable");
}

// csp on the generic drive (on SYNC0: the bus runs distributed clocks for it by default).
TEST(EthercatBusModes, GenericFollowsCspSetpoints) {
  EcatHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("gen", CommandKind::Enable), 3s, "enable");
  expect_completed(h, h.set_mode("gen", Mode::CyclicPosition), 3s, "csp");
  double target = h.snap("gen").position;
  for (int i = 0; i < 300; ++i) {
    target -= 0.002;
    core::Setpoint sp;
    sp.axis = h.axis("gen");
    sp.position = target;
    ASSERT_TRUE(h.runner->push_setpoint(sp));
    h.cycle();
  }
  h.run_until([] { return false; }, 50ms);
  EXPECT_NEAR(h.snap("gen").position, target, 0.05);
  expect_completed(h, h.push("gen", CommandKind::Disable), 3s, "disable");
}

// A parameter written and read back over CoE while the process data runs.
TEST(EthercatBus, ParameterOverCoeWhileCycling) {
  EcatHarness h;
  up(h);
  if (HasFatalFailure()) return;
  const auto good_before = h.cx().counters().good;
  const core::ParamReply w = h.param("gen", true, 0x6081, 0, core::ParamType::U32, "12345");
  EXPECT_TRUE(w.ok) << w.error.view();
  const core::ParamReply r = h.param("gen", false, 0x6081, 0, core::ParamType::U32);
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(r.size, 4U);
  EXPECT_EQ(core::get_u32(r.data, 0), 12345U);
  EXPECT_EQ(h.gen.app->drive().read_object({0x6081, 0}).value, 12345);
  EXPECT_GT(h.cx().counters().good, good_before);
  // The gateway's own objects are refused to clients.
  EXPECT_FALSE(h.bus->access(h.axis("esr")).owner_of({0x1600, 1}).empty());
  EXPECT_FALSE(h.bus->access(h.axis("esr")).owner_of({0x6007, 0}).empty());
  EXPECT_TRUE(h.bus->access(h.axis("esr")).owner_of({0x6081, 0}).empty());
}

// A drive powered off: its axis Lost with the sentence, the others keep cycling; powered on: it is
// found again, re-identified, configured from scratch and back disabled.
TEST(EthercatBusRecovery, PoweredOffSlaveIsLostAndComesBack) {
  EcatHarness h;
  up(h);
  if (HasFatalFailure()) return;
  h.line->power_off(2);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("gen")) == LinkState::Lost; }, 100ms)) << h.details();
  EXPECT_EQ(h.bus->link_detail(h.axis("gen")), "slave 3 (0x1003, generic-cia402): no answer for 3 cycles");
  EXPECT_EQ(h.bus->link_state(h.axis("esr")), LinkState::Operational);
  const auto cx_good = h.cx().inputs_cycle(0);
  h.run_until([] { return false; }, 20ms);
  EXPECT_GT(h.cx().inputs_cycle(0), cx_good);  // the ESR's inputs keep coming
  EXPECT_EQ(h.cx().answered(0), SlaveAnswer::Answered);
  EXPECT_EQ(h.cx().answered(1), SlaveAnswer::Answered);
  EXPECT_EQ(h.cx().answered(2), SlaveAnswer::Missing);
  EXPECT_EQ(h.bus->link_state(h.axis("esr")), LinkState::Operational);
  EXPECT_EQ(h.esr.esc->state(), AlState::Op);

  h.gen.app->power_cycle();
  h.line->power_on(2);
  ASSERT_TRUE(h.run_until([&] { return h.up("gen"); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->restarts(2), 1U);
  EXPECT_EQ(h.gen.esc->state(), AlState::Op);
  EXPECT_EQ(h.snap("gen").state, AxisState::SwitchOnDisabled);
  expect_completed(h, h.push("gen", CommandKind::Enable), 3s, "enable after the restart");
}

// What bench_ethercat_daemon_cpu's phase (b) meets when its simulator stalls (bench/README.md):
// the whole line stops answering for longer than lost_cycles while a drive moves in profile
// position. Every slave is lost and configured from scratch; the axes come back disabled, so a move
// is refused ("axis is not enabled") until an enable; enabled again, the drive moves. The profile
// reaches the restarted slaves' statusword, controlword, mode and target through the image
// references it resolved once, before the loss (ObjectAccess::resolve). (The generic drive moves:
// the simulated ESR takes controlword bit 6 as "absolute" in pp, dunker-ethercat-coe.md
// errata 14, which its device profile does not follow.)
TEST(EthercatBusRecovery, StalledLineLosesTheMovingAxesWhichMoveAgainOnceEnabled) {
  EcatHarness h;
  up(h);
  if (HasFatalFailure()) return;
  expect_completed(h, h.push("esr", CommandKind::Enable), 3s, "enable esr");
  expect_completed(h, h.push("gen", CommandKind::Enable), 3s, "enable gen");
  expect_completed(h, h.push("gen", CommandKind::Move, 2.0, 5.0), 20s, "move gen");
  const auto moving = h.push("gen", CommandKind::Move, 0.0, 5.0);
  h.run_until([] { return false; }, 50ms);
  ASSERT_EQ(h.gen.app->drive().state(), AxisState::OperationEnabled);

  h.line->drop_next(30);  // about 30 cycles without an answer: lost_cycles is 3
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("esr")) == LinkState::Lost &&
                                       h.bus->link_state(h.axis("gen")) == LinkState::Lost; }, 100ms))
      << h.details();
  EXPECT_EQ(h.wait_final(moving, 100ms), ReplyStatus::Failed);
  EXPECT_EQ(h.reason(moving), "link to drive lost");
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_GE(h.bus->restarts(0), 1U);
  EXPECT_GE(h.bus->restarts(2), 1U);
  for (const char* name : {"esr", "gen"}) {
    EXPECT_EQ(h.snap(name).state, AxisState::SwitchOnDisabled) << name;
    const auto refused = h.push(name, CommandKind::Move, 1.0, 5.0);
    EXPECT_EQ(h.wait_final(refused, 100ms), ReplyStatus::Rejected) << name;
    EXPECT_EQ(h.reason(refused), "axis is not enabled: send enable first") << name;
  }

  // Disabled, the drive coasts to a stop; then enabled and moved as before the loss.
  ASSERT_TRUE(h.run_until([&] { return h.gen.app->drive().read_object({0x606C, 0}).value == 0; }, 20s));
  expect_completed(h, h.push("esr", CommandKind::Enable), 3s, "enable esr after the restart");
  expect_completed(h, h.push("gen", CommandKind::Enable), 3s, "enable gen after the restart");
  expect_completed(h, h.push("gen", CommandKind::Move, 1.0, 5.0), 20s, "move gen after the restart");
  EXPECT_NEAR(h.snap("gen").position, 1.0, 0.01);
  EXPECT_NEAR(static_cast<double>(h.gen.app->drive().read_object({0x6064, 0}).value), 4096.0, 41.0);  // counts
  EXPECT_EQ(h.snap("esr").state, AxisState::OperationEnabled);
}

// A slave of another identity at a drive's position is refused, naming both identities.
TEST(EthercatBus, IdentityMismatchIsRefusedWithBothIdentities) {
  EcatHarness h(kLine, false);
  h.make(true);  // a generic drive where the ESR belongs
  const auto mismatch = [&] {
    return h.bus->link_detail(h.axis("esr")).find("identity mismatch") != std::string_view::npos;
  };
  ASSERT_TRUE(h.run_until(mismatch, 1s)) << h.details();
  EXPECT_EQ(h.bus->link_state(h.axis("esr")), LinkState::Offline);
  const std::string detail(h.bus->link_detail(h.axis("esr")));
  EXPECT_NE(detail.find("identity mismatch: expected vendor 0x0000000F product 0x00006755"), std::string::npos) << detail;
  EXPECT_NE(detail.find("found vendor 0x00000000 product 0x00000192"), std::string::npos) << detail;
  EXPECT_NE(h.events_text().find("identity mismatch"), std::string::npos) << h.events_text();
  EXPECT_TRUE(h.run_until([&] { return h.up("gen"); }, 5s)) << h.details();
  // It is tried again after the back-off, and refused again.
  h.run_until([] { return false; }, 300ms);
  EXPECT_NE(h.bus->link_state(h.axis("esr")), LinkState::Operational);
  EXPECT_EQ(h.gen.esc->state(), AlState::Op);
}

}  // namespace
}  // namespace drivegate::ethercat::test

