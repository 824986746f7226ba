// The CANopen bus end to end inside one process: the gateway's CanopenBus and a BusRunner on one
// side of the wire-emulating in-process bus, simulated AKD, NORD SK 500P and STÖBER SD6 drives on
// the other, all on virtual time.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/canopen_bus/bus_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::LinkState;
using core::ReplyStatus;

TEST(CanopenBus, EveryNodeComesUpByItselfDisabled) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_operational(); }, 5s)) << h.events_text();
  ASSERT_TRUE(h.run_until([&] {
    for (const auto& s : h.specs)
      if (h.snap(s.name).state != AxisState::SwitchOnDisabled) return false;
    return true;
  }, 1s)) << h.events_text();
  for (std::size_t i = 0; i < h.specs.size(); ++i) {
    EXPECT_EQ(h.bus->boots(i), 1U) << h.specs[i].name;
    EXPECT_GT(h.bus->pdos(i).counters().tpdos_received, 0U) << h.specs[i].name;
  }
  // The SD6 does not repeat its boot-up after NMT reset communication (quirk 9): it was probed.
  EXPECT_EQ(h.bus->sdo().counters().failed, 0U);
  EXPECT_EQ(h.bus->unexpected_frames(), 0U);
}

TEST(CanopenBus, EnableAndMoveEveryPersonaInProfilePosition) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  for (const char* name : {"akd", "nord", "sd6"}) {
    const auto en = h.push(name, CommandKind::Enable);
    ASSERT_EQ(h.wait_final(en, 3s), ReplyStatus::Completed) << name << ": " << h.reason(en) << h.events_text();
    const auto mv = h.push(name, CommandKind::Move, 2.0);
    ASSERT_EQ(h.wait_final(mv, 20s), ReplyStatus::Completed) << name << ": " << h.reason(mv) << h.events_text();
    EXPECT_NEAR(h.snap(name).position, 2.0, 0.01) << name;
    const auto dis = h.push(name, CommandKind::Disable);
    ASSERT_EQ(h.wait_final(dis, 3s), ReplyStatus::Completed) << name << ": " << h.reason(dis);
  }
}

TEST(CanopenBus, DriveFaultShowsTheProfileTextAndResets) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  const auto en = h.push("sd6", CommandKind::Enable);
  ASSERT_EQ(h.wait_final(en, 3s), ReplyStatus::Completed) << h.reason(en);
  h.drive("sd6").inject_fault(0x4310, 0);  // motor overtemperature, event 41 (SD6 §6.9 Tab. 17)
  ASSERT_TRUE(h.run_until([&] { return h.snap("sd6").state == AxisState::Fault; }, 1s)) << h.events_text();
  ASSERT_TRUE(h.run_until([&] { return h.snap("sd6").fault_code == 0x4310; }, 1s)) << h.events_text();
  const std::string text(h.snap("sd6").fault_text.view());
  EXPECT_NE(text.find("event 41"), std::string::npos) << text;
  // The reset is refused while the cause persists, and succeeds once it is gone.
  h.drive("sd6").clear_fault_cause();
  const auto rs = h.push("sd6", CommandKind::FaultReset);
  ASSERT_EQ(h.wait_final(rs, 3s), ReplyStatus::Completed) << h.reason(rs) << h.events_text();
  EXPECT_EQ(h.snap("sd6").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.snap("sd6").fault_code, 0U);
}

TEST(CanopenBus, PowerLossIsRecoveredAutomaticallyAndComesBackDisabled) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  const auto en = h.push("akd", CommandKind::Enable);
  ASSERT_EQ(h.wait_final(en, 3s), ReplyStatus::Completed) << h.reason(en);
  const auto akd = h.axis("akd");
  h.drive("akd").power_off();
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(akd) == LinkState::Lost; }, 2s)) << h.events_text();
  EXPECT_NE(std::string(h.bus->link_detail(akd)).find("heartbeat"), std::string::npos) << h.bus->link_detail(akd);
  h.drive("akd").power_on();
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(akd) == LinkState::Operational; }, 5s)) << h.events_text();
  ASSERT_TRUE(h.run_until([&] { return h.snap("akd").state == AxisState::SwitchOnDisabled; }, 1s));
  EXPECT_EQ(h.bus->boots(akd), 2U);
  const auto again = h.push("akd", CommandKind::Enable);
  EXPECT_EQ(h.wait_final(again, 3s), ReplyStatus::Completed) << h.reason(again);
  // The other drives never noticed.
  EXPECT_EQ(h.bus->boots(h.axis("nord")), 1U);
}

TEST(CanopenBus, GatewayBusOffTakesEveryNodeDownAndBackUp) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_operational(); }, 5s)) << h.events_text();
  h.peer->set_gateway_bus_off(true);
  ASSERT_TRUE(h.run_until([&] {
    for (std::size_t i = 0; i < h.specs.size(); ++i)
      if (h.bus->link_state(i) != LinkState::Lost) return false;
    return true;
  }, 1s));
  EXPECT_NE(std::string(h.bus->link_detail(0)).find("bus-off"), std::string::npos);
  h.peer->set_gateway_bus_off(false);
  ASSERT_TRUE(h.run_until([&] { return h.all_operational(); }, 10s)) << h.events_text();
}

TEST(CanopenBus, FailedBootNamesTheStepObjectAndAbortAndRetries) {
  std::string yaml = kThreeDrives;
  yaml.replace(yaml.find("homing: { method: 35 } }\n  - { name: nord"), 24,
               "homing: { method: 35 },\n      canopen: { startup_writes: [{ object: \"0x2FFF\", type: u32, value: 1, "
               "why: test object }] } }");
  BusHarness h(yaml);
  const auto akd = h.axis("akd");
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(akd) == LinkState::Offline; }, 5s)) << h.events_text();
  const std::string detail(h.bus->link_detail(akd));
  EXPECT_NE(detail.find("start-up write (axis): write 2FFFh:00"), std::string::npos) << detail;
  EXPECT_NE(detail.find("0x06020000"), std::string::npos) << detail;
  EXPECT_NE(detail.find("test object"), std::string::npos) << detail;
  // The others are not held up, and the failed node is tried again after its back-off.
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("sd6")) == LinkState::Operational; }, 5s));
  const auto boots = h.bus->boots(akd);
  h.run_until([] { return false; }, 3s);
  EXPECT_GT(h.bus->boots(akd), boots);
}

TEST(CanopenBus, CyclesAllocateNothingWhileAxesMove) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  for (const char* name : {"akd", "nord", "sd6"}) {
    const auto en = h.push(name, CommandKind::Enable);
    ASSERT_EQ(h.wait_final(en, 3s), ReplyStatus::Completed) << name << ": " << h.reason(en);
    h.push(name, CommandKind::Move, 50.0);
  }
  h.cycle();
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 1000; ++i) {
    h.now += h.plan.buses[0].cycle_time;
    h.runner->cycle(h.now);
    core::Reply r;
    while (h.runner->pop_reply(r)) {
    }
    core::Event e;
    while (h.runner->pop_event(e)) {
    }
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_GT(std::fabs(h.snap("akd").position), 0.1);
}

}  // namespace
}  // namespace drivegate::canopen::test
