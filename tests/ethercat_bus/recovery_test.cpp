// The EtherCAT bus recovering: the Ethernet link down and up again (every slave lost, then each
// restarted), and the safe stop of a drive that no longer follows its controlword.
#include <gtest/gtest.h>

#include "profiles/cia402/statusword.hpp"
#include "tests/ethercat_bus/bus_harness.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::ReplyStatus;

// The wire goes down for 300 ms (no carrier): every axis Lost with the sentence; the slaves' SM
// watchdogs run out meanwhile (SAFE-OP + error 001Bh, the ESR's 6007h reaction faults it). When
// the wire is back each slave is restarted and configured again; the axes come back.
TEST(EthercatBusRecovery, LinkDownAndUpRecoversEverySlave) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.link->set_wire_state(ethercat::LinkState::NoCarrier);
  h.cycle();
  for (const char* a : {"esr", "gen"}) {
    EXPECT_EQ(h.bus->link_state(h.axis(a)), core::LinkState::Lost) << a;
    EXPECT_EQ(h.bus->link_detail(h.axis(a)), "the Ethernet link is down (no carrier)") << a;
  }
  h.run_until([] { return false; }, 300ms);
  EXPECT_EQ(h.esr.esc->state(), AlState::SafeOp);  // the SM watchdog [ETG.1000.4 §6.7.2]
  h.link->set_wire_state(ethercat::LinkState::Up);
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.bus->restarts(0), 1U);
  EXPECT_EQ(h.bus->restarts(1), 1U);
  EXPECT_EQ(h.bus->restarts(2), 1U);
  EXPECT_EQ(h.esr.esc->state(), AlState::Op);
  EXPECT_EQ(h.panel_esc->state(), AlState::Op);
  EXPECT_EQ(h.gen.esc->state(), AlState::Op);
  EXPECT_GT(h.bus->counters().frames_lost, 0U);
}

// The profile reports the drive out of control: link Degraded, quick stop and disable through the
// process data, SAFE-OP, configured again and back, disabled.
TEST(EthercatBusRecovery, SafeStopWhenControlIsLost) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  ASSERT_EQ(h.wait_final(h.push("gen", CommandKind::Enable), 3s), ReplyStatus::Completed) << h.events_text();
  ASSERT_EQ(h.gen.app->drive().state(), AxisState::OperationEnabled);
  h.bus->access(h.axis("gen")).control_lost("test: the drive ignores its controlword");
  h.cycle();
  EXPECT_EQ(h.bus->link_state(h.axis("gen")), core::LinkState::Degraded);
  EXPECT_EQ(h.bus->link_detail(h.axis("gen")), "test: the drive ignores its controlword");
  ASSERT_TRUE(h.run_until([&] { return h.gen.app->drive().state() != AxisState::OperationEnabled; }, 1s));
  ASSERT_TRUE(h.run_until([&] { return h.bus->restarts(2) == 1U && h.up("gen"); }, 5s)) << h.details();
  EXPECT_EQ(h.snap("gen").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.bus->link_state(h.axis("esr")), core::LinkState::Operational);
  bool degraded_seen = false;
  for (const auto& e : h.events)
    degraded_seen = degraded_seen || std::string(e.text.view()).find("-> degraded") != std::string::npos;
  EXPECT_TRUE(degraded_seen) << h.events_text();
}

}  // namespace
}  // namespace drivegate::ethercat::test

namespace drivegate::ethercat::test {
namespace {

// A drive fault the drive announces by CoE emergency [ETG.1000.6 §5.6.4]: an `emcy` event of its
// axis with the device profile's text, and the profile's fault report.
TEST(EthercatBusEmcy, DriveFaultEmergencyBecomesAnEventAndTheFaultReport) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.gen.app->inject_fault(0x2310);
  const auto emcy = [&] {
    for (const auto& e : h.events)
      if (e.kind == core::EventKind::Emcy && e.code == 0x2310) return true;
    return false;
  };
  ASSERT_TRUE(h.run_until(emcy, 500ms)) << h.events_text();
  std::string text;
  for (const auto& e : h.events)
    if (e.kind == core::EventKind::Emcy) text = std::string(e.text.view());
  EXPECT_NE(text.find("EMCY 0x2310"), std::string::npos) << text;
  EXPECT_NE(text.find("Continuous over-current"), std::string::npos) << text;  // generic-cia402.yaml
  const cia402::DriveFaultReport r = h.bus->access(h.axis("gen")).fault_report();
  EXPECT_TRUE(r.valid);
  EXPECT_EQ(r.code, 0x2310);
  EXPECT_EQ(r.text, "Continuous over-current");
  ASSERT_TRUE(h.run_until([&] { return h.snap("gen").state == core::AxisState::Fault; }, 500ms));
  EXPECT_EQ(h.bus->link_state(h.axis("gen")), core::LinkState::Operational);
}

// close(): every slave to SAFE-OP, then INIT, and the link closed.
TEST(EthercatBusClose, TakesTheSlavesDownToInit) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details();
  h.bus->close();
  EXPECT_EQ(h.esr.esc->state(), AlState::Init);
  EXPECT_EQ(h.panel_esc->state(), AlState::Init);
  EXPECT_EQ(h.gen.esc->state(), AlState::Init);
  EXPECT_FALSE(h.link->is_open());
  EXPECT_EQ(h.bus->link_state(h.axis("esr")), core::LinkState::Offline);
}

}  // namespace
}  // namespace drivegate::ethercat::test
