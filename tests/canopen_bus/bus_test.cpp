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

// NORD: 6060h in RxPDO1 is never 0, not even before the first status (quirk mode_object_always_valid).
TEST(CanopenBus, NordModeByteIsValidFromTheFirstRpdo) {
  BusHarness h;
  const auto nord = h.axis("nord");
  EXPECT_EQ(h.bus->pdos(nord).image().get(cia402::obj::kModesOfOperation.id), 1);  // pp: the first mode it offers
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  EXPECT_EQ(h.drive("nord").counters().refused_pdo_values, 0U);
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

// The link events of an axis, in order.
std::vector<std::string> link_events(const BusHarness& h, core::AxisIndex axis) {
  std::vector<std::string> v;
  for (const auto& e : h.events)
    if (e.axis == axis && e.kind == core::EventKind::LinkChanged) v.emplace_back(e.text.view());
  return v;
}

// A cut cable: the AKD runs on and does not boot again, so when it answers again it is found by
// the probe. Every link event says what its own transition did, never the failure before it (a
// field report read "link lost -> configuring: node 35 stopped answering").
TEST(CanopenBus, EveryLinkEventSaysWhatItsOwnTransitionDid) {
  BusHarness h;
  const auto akd = h.axis("akd");
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  ASSERT_FALSE(link_events(h, akd).empty());
  EXPECT_EQ(link_events(h, akd).back(), "link configuring -> operational: node 1 configured") << h.events_text();

  h.events.clear();
  h.drive("akd").set_silent(true);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(akd) == LinkState::Lost; }, 2s)) << h.events_text();
  // Probed (and failing) while the cable is cut: the link stays lost, no new event.
  h.run_until([] { return false; }, 3s);
  EXPECT_EQ(h.bus->link_state(akd), LinkState::Lost);
  h.drive("akd").set_silent(false);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(akd) == LinkState::Operational; }, 15s)) << h.events_text();
  EXPECT_EQ(h.bus->boots(akd), 2U);

  const auto links = link_events(h, akd);
  ASSERT_EQ(links.size(), 3U) << h.events_text();
  EXPECT_EQ(links[0], "link operational -> lost: node 1 stopped answering (heartbeat timeout)");
  EXPECT_EQ(links[1], "link lost -> configuring: node 1 answered again; configuring it");
  EXPECT_EQ(links[2], "link configuring -> operational: node 1 configured");
  for (std::size_t i = 1; i < links.size(); ++i) {
    EXPECT_EQ(links[i].find("stopped answering"), std::string::npos) << links[i];
    EXPECT_EQ(links[i].find("does not answer"), std::string::npos) << links[i];
  }
}

// EMCYs that are not the drive's fault (a warning, error reset / no error 0000h) are events of
// their axis: one each, with code, error register, vendor bytes and the device profile's text.
TEST(CanopenBus, EveryEmcyIsAnEventWithItsCodeRegisterAndVendorBytes) {
  BusHarness h;
  const auto akd = h.axis("akd");
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  const auto emcys = [&] {
    std::vector<core::Event> v;
    for (const auto& e : h.events)
      if (e.kind == core::EventKind::Emcy) v.push_back(e);
    return v;
  };
  EXPECT_TRUE(emcys().empty()) << h.events_text();

  // AKD n502 "DC bus undervoltage" (akd part 1 §9.4), category 1 in byte 3.
  Emcy warning;
  warning.code = 0x3280;
  warning.error_register = 0x05;
  warning.vendor = {0x01, 0x22, 0x33, 0x44, 0x55};
  ASSERT_TRUE(h.drive("akd").send_emcy(warning));
  ASSERT_TRUE(h.run_until([&] { return !emcys().empty(); }, 1s)) << h.events_text();
  h.run_until([] { return false; }, 100ms);
  auto got = emcys();
  ASSERT_EQ(got.size(), 1U) << h.events_text();
  EXPECT_EQ(got[0].axis, akd);
  EXPECT_EQ(got[0].code, 0x3280U);
  EXPECT_EQ(got[0].text.view(),
            "EMCY 0x3280 n502: Warning: DC bus undervoltage (category 1); register 0x05, vendor bytes 01 22 33 44 55");
  EXPECT_EQ(got[0].state, AxisState::SwitchOnDisabled);  // a warning: the drive is not in fault
  EXPECT_EQ(h.snap("akd").fault_code, 0U);

  // The all-clear: 0000h with register 0.
  Emcy reset;
  reset.vendor = {0x00, 0x00, 0x00, 0x00, 0x07};
  ASSERT_TRUE(h.drive("akd").send_emcy(reset));
  ASSERT_TRUE(h.run_until([&] { return emcys().size() > 1; }, 1s)) << h.events_text();
  h.run_until([] { return false; }, 100ms);
  got = emcys();
  ASSERT_EQ(got.size(), 2U) << h.events_text();
  EXPECT_EQ(got[1].axis, akd);
  EXPECT_EQ(got[1].code, 0U);
  EXPECT_EQ(got[1].text.view(),
            "EMCY 0x0000 No emergency error (error reset / no error) (category 0); register 0x00, vendor bytes 00 00 "
            "00 00 07");
  EXPECT_EQ(h.bus->emcy_events_dropped(), 0U);
  for (const auto& e : h.events) EXPECT_NE(e.kind, core::EventKind::Fault) << e.text.view();
}

// A node that floods EMCYs cannot flood the event topic: kEmcyBurst at once, then one per second;
// the rest are counted and summed up in one warning.
TEST(CanopenBus, AnEmcyFloodIsBoundedAndCounted) {
  BusHarness h;
  const auto akd = h.axis("akd");
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  h.events.clear();
  Emcy warning;
  warning.code = 0x86A9;  // n167 software limit exceeded
  warning.error_register = 0x01;
  int sent = 0;
  // 50 EMCYs within 200 ms (the simulated drive queues up to 8 and sends one per cycle).
  for (int cycle = 0; cycle < 50; ++cycle) {
    if (h.drive("akd").send_emcy(warning)) ++sent;
    h.cycle();
  }
  h.run_until([] { return false; }, 100ms);  // sent, but not a second later
  const auto count = [&](core::EventKind kind) {
    std::size_t n = 0;
    for (const auto& e : h.events) n += e.axis == akd && e.kind == kind ? 1U : 0U;
    return n;
  };
  ASSERT_EQ(sent, 50);
  EXPECT_EQ(count(core::EventKind::Emcy), CanopenBus::kEmcyBurst) << h.events_text();
  EXPECT_EQ(h.bus->emcy_events_dropped(), 50U - CanopenBus::kEmcyBurst);
  // A second later the node has a token again: one warning says what was held back.
  h.run_until([] { return false; }, 1s);
  EXPECT_EQ(count(core::EventKind::Emcy), CanopenBus::kEmcyBurst) << h.events_text();
  ASSERT_EQ(count(core::EventKind::Warning), 1U) << h.events_text();
  std::string summary;
  for (const auto& e : h.events)
    if (e.axis == akd && e.kind == core::EventKind::Warning) summary = std::string(e.text.view());
  EXPECT_NE(summary.find("node 1 sent 42 EMCYs that were not published"), std::string::npos) << summary;
  EXPECT_NE(summary.find("0x86A9"), std::string::npos) << summary;
  // Quiet again: the bucket refills and the next EMCY is published at once.
  h.run_until([] { return false; }, 8s);
  ASSERT_TRUE(h.drive("akd").send_emcy(warning));
  h.run_until([] { return false; }, 100ms);
  EXPECT_EQ(count(core::EventKind::Emcy), CanopenBus::kEmcyBurst + 1) << h.events_text();
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

// The cyclic path allocates nothing (DESIGN.md §3), also while it handles commands, parameter
// requests over SDO, a drive fault with its EMCY and reset, and a node that loses power, goes lost,
// comes back and is configured again: all of it inside the measured window.
TEST(CanopenBus, CyclesAllocateNothingWhileAxesMove) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  for (const char* name : {"akd", "nord", "sd6"}) {
    const auto en = h.push(name, CommandKind::Enable);
    ASSERT_EQ(h.wait_final(en, 3s), ReplyStatus::Completed) << name << ": " << h.reason(en);
    h.push(name, CommandKind::Move, 50.0);
  }
  h.cycle();
  core::ParamRequest read = drivegate::test::param_read(0, 0x6064, 0, core::ParamType::I32);
  read.axis = h.axis("sd6");
  std::size_t params = 0, replies = 0, faults = 0, links = 0, emcys = 0;
  const auto drain = [&] {
    core::Reply r;
    while (h.runner->pop_reply(r)) ++replies;
    core::Event e;
    while (h.runner->pop_event(e)) {
      faults += e.kind == core::EventKind::Fault ? 1U : 0U;
      emcys += e.kind == core::EventKind::Emcy ? 1U : 0U;
      links += e.kind == core::EventKind::LinkChanged ? 1U : 0U;
    }
    core::ParamReply p;
    while (h.runner->pop_parameter_reply(p)) params += p.ok ? 1U : 0U;
  };
  core::Command cmd;
  cmd.axis = h.axis("akd");
  const drivegate::test::AllocationScope scope;
  for (int i = 0; i < 2000; ++i) {
    if (i % 50 == 0) {  // parameter requests and commands between cyclic traffic
      read.id = 100000 + static_cast<core::CommandId>(i);
      ASSERT_TRUE(h.runner->push_parameter(read));
      cmd.id = 200000 + static_cast<core::CommandId>(i);
      cmd.kind = CommandKind::Move;
      cmd.position = i % 100 == 0 ? 10.0 : 40.0;
      ASSERT_TRUE(h.runner->push_command(cmd));
    }
    if (i == 200) h.drive("sd6").inject_fault(0x4310, 2);  // a drive fault with its EMCY
    if (i >= 250 && i < 270) {  // warnings, more than are published: events, then held back and counted
      Emcy warning;
      warning.code = 0x3280;
      warning.error_register = 0x01;
      h.drive("akd").send_emcy(warning);
    }
    if (i == 300) {
      h.drive("sd6").clear_fault_cause();
      cmd.id = 300000;
      cmd.axis = h.axis("sd6");
      cmd.kind = CommandKind::FaultReset;
      ASSERT_TRUE(h.runner->push_command(cmd));
      cmd.axis = h.axis("akd");
    }
    if (i == 400) h.drive("nord").power_off();  // a node lost ...
    if (i == 700) h.drive("nord").power_on();   // ... back, booted and configured again
    h.now += h.plan.buses[0].cycle_time;
    h.runner->cycle(h.now);
    drain();
  }
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_GT(std::fabs(h.snap("akd").position), 0.1);
  // What the window was to hold really happened in it.
  EXPECT_GE(params, 20U);
  EXPECT_GE(faults, 1U);
  EXPECT_GE(emcys, CanopenBus::kEmcyBurst);
  EXPECT_GT(h.bus->emcy_events_dropped(), 0U);
  EXPECT_GE(links, 2U);  // nord: operational -> lost -> ... -> operational
  EXPECT_EQ(h.bus->link_state(h.axis("nord")), LinkState::Operational) << h.events_text();
  EXPECT_GT(replies, 40U);
}

}  // namespace
}  // namespace drivegate::canopen::test

namespace drivegate::canopen::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::Mode;
using core::ReplyStatus;

core::CommandId set_mode(BusHarness& h, const std::string& axis, Mode m) {
  core::Command c;
  c.id = h.next_id++;
  c.axis = h.axis(axis);
  c.kind = CommandKind::SetMode;
  c.mode = m;
  EXPECT_TRUE(h.runner->push_command(c));
  return c.id;
}

void expect_completed(BusHarness& h, core::CommandId id, core::Duration budget, const std::string& what) {
  ASSERT_EQ(h.wait_final(id, budget), ReplyStatus::Completed) << what << ": " << h.reason(id) << h.events_text();
}

// A velocity or torque command runs until something ends it: accepted now, no final reply while
// it runs (it completes when the client's next command takes over).
void expect_running(BusHarness& h, core::CommandId id, const std::string& what) {
  ASSERT_EQ(h.wait_final(id, 200ms), ReplyStatus::Accepted) << what << ": " << h.reason(id) << h.events_text();
  bool accepted = false;
  for (const auto& r : h.replies) accepted = accepted || (r.id == id && r.status == ReplyStatus::Accepted);
  ASSERT_TRUE(accepted) << what << h.events_text();
}

// Every mode each persona offers, over PDOs and SDOs on the emulated wire.
TEST(CanopenBusModes, AkdVelocityTorqueHomingAndCyclicPosition) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  expect_completed(h, h.push("akd", CommandKind::Enable), 3s, "enable");

  const auto pv = h.push("akd", CommandKind::Velocity, 0, 20.0);
  expect_running(h, pv, "pv velocity");
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("akd").velocity - 20.0) < 0.5; }, 3s)) << h.snap("akd").velocity;
  EXPECT_EQ(h.snap("akd").mode, Mode::ProfileVelocity);
  expect_completed(h, h.push("akd", CommandKind::Stop), 5s, "stop");
  expect_completed(h, pv, 0s, "pv velocity ended by the stop");
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("akd").velocity) < 0.01; }, 3s));

  core::Command tq;
  tq.id = h.next_id++;
  tq.axis = h.axis("akd");
  tq.kind = CommandKind::Torque;
  tq.torque = 5.0;
  ASSERT_TRUE(h.runner->push_command(tq));
  expect_running(h, tq.id, "torque");
  ASSERT_TRUE(h.run_until([&] { return h.snap("akd").mode == Mode::ProfileTorque; }, 3s));
  // Without torque the unloaded simulated motor coasts on: take the power off and start again.
  expect_completed(h, h.push("akd", CommandKind::Disable), 3s, "disable after torque");
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("akd").velocity) < 0.001; }, 20s)) << h.snap("akd").velocity;
  expect_completed(h, h.push("akd", CommandKind::Enable), 3s, "enable again");

  expect_completed(h, h.push("akd", CommandKind::Home), 10s, "homing");
  EXPECT_TRUE(h.snap("akd").homed);

  // csp: set-points streamed every cycle, the position follows.
  expect_completed(h, set_mode(h, "akd", Mode::CyclicPosition), 3s, "csp");
  double target = h.snap("akd").position;
  for (int i = 0; i < 250; ++i) {
    target += 0.02;  // 5 mm/s at 4 ms
    core::Setpoint sp;
    sp.axis = h.axis("akd");
    sp.position = target;
    ASSERT_TRUE(h.runner->push_setpoint(sp));
    h.cycle();
  }
  EXPECT_NEAR(h.snap("akd").position, target, 0.2);

  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("akd").velocity) < 0.001; }, 2s));

  // ip: the same through 60C1h:1 with interpolation enabled (controlword bit 4).
  expect_completed(h, set_mode(h, "akd", Mode::InterpolatedPosition), 3s, "ip");
  for (int i = 0; i < 250; ++i) {
    target -= 0.02;
    core::Setpoint sp;
    sp.axis = h.axis("akd");
    sp.position = target;
    ASSERT_TRUE(h.runner->push_setpoint(sp));
    h.cycle();
  }
  EXPECT_NEAR(h.snap("akd").position, target, 0.2);
  expect_completed(h, h.push("akd", CommandKind::Disable), 3s, "disable");
}

TEST(CanopenBusModes, NordVelocityModeNeedsTheVlBitsAndRuns) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  expect_completed(h, h.push("nord", CommandKind::Enable), 3s, "enable");
  expect_completed(h, set_mode(h, "nord", Mode::Velocity), 3s, "vl");
  expect_running(h, h.push("nord", CommandKind::Velocity, 0, 5.0), "vl velocity");
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("nord").velocity - 5.0) < 0.2; }, 5s))
      << h.snap("nord").velocity << h.events_text();
  EXPECT_EQ(h.snap("nord").mode, Mode::Velocity);
  // The drive only runs with controlword bits 4..6 set (NORD §13 step 8: 0x007F).
  EXPECT_EQ(h.drive("nord").drive().read_object({0x6040, 0}).value & 0x7F, 0x7F);
  expect_completed(h, h.push("nord", CommandKind::Stop), 5s, "stop");
  // Quick stop ends in Switch on disabled on this drive (NORD quirk 13).
  expect_completed(h, h.push("nord", CommandKind::QuickStop), 5s, "quick stop");
  EXPECT_EQ(h.snap("nord").state, AxisState::SwitchOnDisabled);
}

TEST(CanopenBusModes, Sd6ProfileVelocityAndHoming) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  expect_completed(h, h.push("sd6", CommandKind::Enable), 3s, "enable");
  expect_running(h, h.push("sd6", CommandKind::Velocity, 0, 3.0), "pv");
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("sd6").velocity - 3.0) < 0.1; }, 5s)) << h.snap("sd6").velocity;
  expect_completed(h, h.push("sd6", CommandKind::Stop), 5s, "stop");
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("sd6").velocity) < 0.01; }, 3s));
  expect_completed(h, h.push("sd6", CommandKind::Home), 10s, "homing");
  EXPECT_TRUE(h.snap("sd6").homed);
}

}  // namespace
}  // namespace drivegate::canopen::test

namespace drivegate::canopen::test {
namespace {

// Malformed and unexpected frames from a third device on the wire are counted and dropped; no node
// changes state because of them.
TEST(CanopenBusBadInput, StrayFramesAreCountedAndChangeNothing) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  auto rogue = h.peer->bus().connect();
  rogue->open();
  const std::vector<CanFrame> junk{
      make_frame(0x581, {0x43, 0x00, 0x10}),                                   // SDO response, wrong DLC
      make_frame(0x581, {0xE0, 0, 0, 0, 0, 0, 0, 0}),                          // unknown specifier
      make_frame(0x582, {0x60, 0x17, 0x10, 0, 0, 0, 0, 0}),                    // a response nobody asked for
      make_frame(0x5A5, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}),     // from an unconfigured node
      make_frame(0x185, {0x37, 0x02}),                                         // TPDO of an unconfigured node
      make_frame(0x181, {0x37}),                                               // TPDO1 of node 1, too short
      make_frame(0x701, {0x05, 0x00}),                                         // heartbeat, wrong DLC
      make_frame(0x701, {0x42}),                                               // heartbeat, no such state
      make_frame(0x081, {0x10}),                                               // EMCY too short
      make_frame(0x77F, {0x05}),                                               // heartbeat of an unknown node
  };
  const auto dropped_before = h.bus->counters().frames_dropped;
  for (int round = 0; round < 20; ++round) {
    for (const auto& f : junk) ASSERT_EQ(rogue->send(f, h.now), SendResult::Sent);
    h.cycle();
  }
  h.run_until([] { return false; }, 200ms);
  EXPECT_TRUE(h.all_operational()) << h.events_text();
  for (std::size_t i = 0; i < h.specs.size(); ++i) EXPECT_EQ(h.bus->boots(i), 1U) << h.specs[i].name;
  EXPECT_GE(h.bus->counters().frames_dropped - dropped_before, 20U * 8U);
  // And the axes still work.
  const auto en = h.push("akd", CommandKind::Enable);
  EXPECT_EQ(h.wait_final(en, 3s), ReplyStatus::Completed) << h.reason(en);
}

}  // namespace
}  // namespace drivegate::canopen::test

namespace drivegate::canopen::test {
namespace {

// Parameter requests go over the node's SDO channel between the cyclic PDOs; an abort comes back
// with its code and text.
TEST(CanopenBusParameters, ReadsWritesAndAbortsOverSdo) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  std::vector<core::ParamReply> got;
  using core::ParamType;
  auto ask = [&](const std::string& axis, bool write, std::uint16_t index, std::uint8_t sub, ParamType type,
                 std::string_view value = {}) { return h.param(axis, write, index, sub, type, value); };
  auto r = ask("akd", false, 0x1018, 1, ParamType::U32);
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(drivegate::test::reply_integer(r), 0x6A);  // Kollmorgen (AKD part 1 §14 vector 11)
  r = ask("sd6", false, 0x1018, 1, ParamType::U32);
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(drivegate::test::reply_integer(r), 0xB9);  // STÖBER, answered with 42h (SD6 D-2)
  r = ask("sd6", false, 0x2053, 0, ParamType::U8);  // A83: the node-ID
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(drivegate::test::reply_integer(r), 3);
  r = ask("nord", false, 0x603F, 0, ParamType::U16);  // NORD has no 603Fh (NORD §9)
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error_code, 0x06020000U);
  EXPECT_NE(std::string(r.error.view()).find("does not exist"), std::string::npos) << r.error.view();
  r = ask("akd", true, 0x6081, 0, ParamType::U32, "12345");
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(h.drive("akd").drive().read_object({0x6081, 0}).value, 12345);
}

}  // namespace
}  // namespace drivegate::canopen::test

namespace drivegate::canopen::test {
namespace {

// An orderly stop of the gateway is not a lost gateway: the drives are told to stop watching it
// before its heartbeat ends, and none of them faults afterwards.
TEST(CanopenBusShutdown, OrderlyCloseReleasesTheDrivesWatchdogs) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  h.bus->close();  // takes up to a few hundred ms of real time past the last cycle
  auto t = h.now + 1s;
  for (int i = 0; i < 500; ++i) {  // 2 s more, far beyond every heartbeat and life time
    t += 4ms;
    h.peer->step(t);
  }
  for (const char* name : {"akd", "nord", "sd6"}) {
    EXPECT_EQ(h.drive(name).counters().comm_losses, 0U) << name;
    EXPECT_EQ(h.drive(name).fault_code(), 0U) << name;
  }
}

}  // namespace
}  // namespace drivegate::canopen::test

namespace drivegate::canopen::test {
namespace {

// A completed move is a standstill a client can act on: the next command in another mode is
// accepted at once, also on an axis without a velocity limit (standstill window 0.01 unit/s).
TEST(CanopenBusModes, ModeChangeRightAfterACompletedMove) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  ASSERT_EQ(h.wait_final(h.push("akd", CommandKind::Enable), 3s), ReplyStatus::Completed);
  const auto mv = h.push("akd", CommandKind::Move, 3.0);
  ASSERT_EQ(h.wait_final(mv, 20s), ReplyStatus::Completed) << h.reason(mv);
  const auto jog = h.push("akd", CommandKind::Velocity, 0, 5.0);
  ASSERT_NO_FATAL_FAILURE(expect_running(h, jog, "velocity right after the move"));
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("akd").velocity - 5.0) < 0.2; }, 3s)) << h.snap("akd").velocity;
}

}  // namespace
}  // namespace drivegate::canopen::test
