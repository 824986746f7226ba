// Faults injected in the simulator process: a drive fault with the device profile's text, a drive
// that loses power and comes back, and a gateway that dies under the drives.
#include <cmath>

#include "tests/canopen_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

using client::AxisState;
using client::Outcome;

class CanopenE2eFaults : public CanopenE2eUp {
 protected:
  void enable(const std::string& axis) {
    const auto r = send(axis, "enable");
    ASSERT_EQ(r.outcome, Outcome::Completed) << axis << ": " << r.reason << diagnostics();
  }

  void sim_command(const std::string& line, const std::string& answer) {
    ASSERT_EQ(sim_->command(line), answer) << line << diagnostics();
  }

  // Streams the jog's keep-alive until the axis runs at `velocity`.
  void jog(const std::string& axis, double velocity) {
    auto v = request(axis, "velocity");
    v.velocity = velocity;
    const auto r = start(v);
    ASSERT_EQ(r.outcome, Outcome::Accepted) << axis << ": " << r.reason << diagnostics();
    ASSERT_TRUE(keep_alive_until(axis, 0, velocity, 0, [&](const AxisState& s) {
      return std::fabs(s.velocity - velocity) < 0.1 * velocity;
    }, 5s)) << diagnostics();
  }
};

// The fault text a person reads comes from the device profile: the AKD's F-number, the NORD's
// E-number (its EMCY table), the SD6's Tab. 17 text with the event and cause bytes of its EMCY.
TEST_F(CanopenE2eFaults, DriveFaultShowsTheProfileTextAndResetsOnceTheCauseIsGone) {
  for (const char* axis : {"akd", "nord", "sd6"}) ASSERT_NO_FATAL_FAILURE(enable(axis));

  ASSERT_NO_FATAL_FAILURE(sim_command("fault 1 0x4310", "ok fault node 1 0x4310"));
  ASSERT_NO_FATAL_FAILURE(sim_command("fault 2 0x2310", "ok fault node 2 0x2310"));
  ASSERT_NO_FATAL_FAILURE(sim_command("fault 3 0x4310 2", "ok fault node 3 0x4310"));
  const auto shows = [&](const std::string& axis, std::uint32_t code, const std::string& text) {
    EXPECT_TRUE(wait_axis(axis, [&](const AxisState& s) {
      return s.state == "fault" && s.fault_code == code && s.fault_text.find(text) != std::string::npos;
    }, 3s)) << axis << " should show 0x" << std::hex << code << std::dec << " \"" << text << "\"" << diagnostics();
    EXPECT_TRUE(wait_event(axis, "fault", text, 1s)) << axis;
  };
  shows("akd", 0x4310, "F235: Heat sink temperature too high");                // akd part 1 §9.4
  shows("nord", 0x2310, "E3.0: inverter overcurrent");                         // nord §9
  shows("sd6", 0x4310, "Drive temperature (event 41: motor overtemperature");  // sd6 §6.9 Tab. 17
  EXPECT_NE(state("sd6").fault_text.find("(event 41, cause 2)"), std::string::npos) << state("sd6").fault_text;
  if (HasFailure()) return;

  // While the cause persists the drive stays in fault: the reset fails and says why.
  const auto early = send("akd", "fault_reset", 5s);
  EXPECT_EQ(early.outcome, Outcome::Failed) << early.reason;
  EXPECT_NE(early.reason.find("cause still present"), std::string::npos) << early.reason;
  EXPECT_EQ(state("akd").state, "fault");

  for (const char* node : {"1", "2", "3"})
    ASSERT_NO_FATAL_FAILURE(sim_command(std::string("clear ") + node, std::string("ok clear node ") + node));
  for (const char* axis : {"akd", "nord", "sd6"}) {
    const auto r = send(axis, "fault_reset");
    EXPECT_EQ(r.outcome, Outcome::Completed) << axis << ": " << r.reason << diagnostics();
    EXPECT_TRUE(wait_axis(axis, [](const AxisState& s) {
      return s.state == "switch_on_disabled" && s.fault_code == 0 && s.fault_text.empty();
    }, 2s)) << axis << diagnostics();
    EXPECT_TRUE(wait_event(axis, "fault_cleared", "", 1s)) << axis;
  }
  std::string status;
  EXPECT_TRUE(sim_->wait_status([](const std::string& s) {
    for (int node : {1, 2, 3}) {
      if (node_status(s, "can0", node).find("state=switch_on_disabled fault=0x0000") == std::string::npos) return false;
    }
    return true;
  }, 2s, status)) << status;
}

// EMCYs that are not the drive's fault reach the event topic: a warning and the all-clear 0000h,
// one event each, with the EMCY code in `code` and register and vendor bytes in the text.
TEST_F(CanopenE2eFaults, WarningAndErrorResetEmcysArePublishedAsEvents) {
  ASSERT_NO_FATAL_FAILURE(sim_command("emcy 1 0x3280 0x05 1 0x22 0x33 0x44 0x55", "ok emcy node 1 0x3280"));
  const std::string warning =
      "EMCY 0x3280 n502: Warning: DC bus undervoltage (category 1); register 0x05, vendor bytes 01 22 33 44 55";
  ASSERT_TRUE(wait_event("akd", "emcy", warning, 3s)) << diagnostics();
  ASSERT_NO_FATAL_FAILURE(sim_command("emcy 1 0 0", "ok emcy node 1 0x0000"));
  ASSERT_TRUE(wait_event("akd", "emcy", "EMCY 0x0000 No emergency error (error reset / no error)", 3s))
      << diagnostics();
  std::vector<client::AxisEvent> emcys;
  for (const auto& e : events())
    if (e.kind == "emcy") emcys.push_back(e);
  ASSERT_EQ(emcys.size(), 2u) << diagnostics();
  EXPECT_EQ(emcys[0].text, warning);
  EXPECT_EQ(emcys[0].code, 0x3280u);
  EXPECT_EQ(emcys[0].state, "switch_on_disabled");
  EXPECT_EQ(emcys[1].code, 0u);
  EXPECT_NE(emcys[1].text.find("register 0x00, vendor bytes 00 00 00 00 00"), std::string::npos) << emcys[1].text;
  EXPECT_EQ(state("akd").state, "switch_on_disabled");
  EXPECT_EQ(state("akd").fault_code, 0u);
}

// A drive that loses power is lost (the AKD's heartbeat stops, the SD6 stops answering node
// guarding), comes back by itself when powered again, configured from scratch and disabled, and
// can be enabled again. The NORD on the same bus never notices.
TEST_F(CanopenE2eFaults, PowerLossIsRecoveredByItselfAndComesBackDisabled) {
  ASSERT_NO_FATAL_FAILURE(enable("akd"));
  ASSERT_NO_FATAL_FAILURE(enable("sd6"));
  ASSERT_NO_FATAL_FAILURE(sim_command("power-off 1", "ok power-off node 1"));
  ASSERT_NO_FATAL_FAILURE(sim_command("power-off 3", "ok power-off node 3"));
  EXPECT_TRUE(wait_axis("akd", [](const AxisState& s) { return s.link == "lost"; }, 3s)) << diagnostics();
  EXPECT_TRUE(wait_axis("sd6", [](const AxisState& s) { return s.link == "lost"; }, 3s)) << diagnostics();
  EXPECT_TRUE(wait_event("akd", "link_changed", "heartbeat", 1s)) << diagnostics();
  EXPECT_TRUE(wait_event("sd6", "link_changed", "node guarding", 1s)) << diagnostics();
  std::string status;
  EXPECT_TRUE(sim_->wait_status([](const std::string& s) {
    return node_status(s, "can0", 1) == "can0:1 akd off" && node_status(s, "can0", 3) == "can0:3 stoeber-sd6 off";
  }, 1s, status)) << status;
  if (HasFailure()) return;

  ASSERT_NO_FATAL_FAILURE(sim_command("power-on 1", "ok power-on node 1"));
  ASSERT_NO_FATAL_FAILURE(sim_command("power-on 3", "ok power-on node 3"));
  ASSERT_TRUE(wait_all("switch_on_disabled", 10s)) << diagnostics();
  // Reconfigured from scratch after the boot-up (AKD) or the probe (SD6). Each link event says what
  // its own transition did, not the loss before it.
  for (const char* axis : {"akd", "sd6"}) {
    EXPECT_TRUE(wait_event(axis, "link_changed", "link lost -> configuring", 1s)) << axis << diagnostics();
    EXPECT_TRUE(wait_event(axis, "link_changed", "link configuring -> operational: node", 1s)) << axis << diagnostics();
    for (const auto& e : events()) {
      if (e.axis != axis || e.kind != "link_changed" || e.text.find("link lost -> ") == std::string::npos) continue;
      EXPECT_EQ(e.text.find("stopped answering"), std::string::npos) << e.text;
      EXPECT_EQ(e.text.find("heartbeat"), std::string::npos) << e.text;
      EXPECT_EQ(e.text.find("node guarding"), std::string::npos) << e.text;
      EXPECT_NE(e.text.find("configuring it"), std::string::npos) << e.text;
    }
  }
  for (const char* axis : {"akd", "sd6"}) {
    const auto r = send(axis, "enable");
    EXPECT_EQ(r.outcome, Outcome::Completed) << axis << ": " << r.reason << diagnostics();
  }
  // The NORD's link never changed after it first came up.
  for (const auto& e : events()) {
    if (e.axis == "nord" && e.kind == "link_changed") {
      EXPECT_EQ(e.text.find("lost"), std::string::npos) << e.text;
    }
  }
  EXPECT_EQ(state("nord").link, "operational");
}

// SIGKILL drivegated while the drives run: the AKD and the NORD miss the gateway's heartbeat
// (their 1016h consumer), the SD6 misses node guarding (life guarding, in Operational), and each
// faults: AKD F129 "decelerates to standstill and blocks any further motion" (akd part 1 §11),
// SD6 event 52 cause 1 (sd6 §4.1, §4.4), NORD E10 telegram timeout (its profile's assumption). A
// new gateway finds them faulted and stopped, and resets them.
TEST_F(CanopenE2eFaults, GatewayKilledTheDrivesNoticeAndFault) {
  for (const char* axis : {"akd", "nord", "sd6"}) ASSERT_NO_FATAL_FAILURE(enable(axis));
  ASSERT_NO_FATAL_FAILURE(jog("akd", 20));
  ASSERT_NO_FATAL_FAILURE(jog("sd6", 3));

  ASSERT_NO_FATAL_FAILURE(kill_gateway());
  std::string status;
  ASSERT_TRUE(sim_->wait_status([](const std::string& s) {
    return node_status(s, "can0", 1).find("state=fault fault=0x8130") != std::string::npos &&
           node_status(s, "can0", 2).find("state=fault fault=0x8100") != std::string::npos &&
           node_status(s, "can0", 3).find("state=fault fault=0x7500") != std::string::npos;
  }, 3s, status)) << status << "\n" << sim_->log();
  // Still operational on the NMT side: nothing told them otherwise.
  for (int node : {1, 2, 3}) EXPECT_NE(node_status(status, "can0", node).find("nmt=operational"), std::string::npos);

  // A gateway started again probes the running drives, reconfigures them and shows their faults.
  // A new client talks to it: the old one still counts the killed gateway's endpoints as matched
  // until their lease ends, so it may send before it matched the new gateway, and lose that.
  ASSERT_NO_FATAL_FAILURE(start_gateway());
  connect_client();
  ASSERT_TRUE(wait_all("fault", kStartUp)) << diagnostics();
  EXPECT_TRUE(wait_axis("akd", [](const AxisState& s) {
    return s.fault_code == 0x8130 && s.fault_text.find("F129") != std::string::npos;
  }, 2s)) << diagnostics();
  EXPECT_TRUE(wait_axis("sd6", [](const AxisState& s) {
    return s.fault_code == 0x7500 && s.fault_text.find("event 52") != std::string::npos;
  }, 2s)) << diagnostics();
  // The NORD has no 603Fh (nord §9, quirk 20): its EMCY went out while no gateway listened, so
  // the new one can only say that the drive is in fault and why it cannot name it.
  EXPECT_NE(state("nord").fault_text.find("603Fh unreadable"), std::string::npos) << diagnostics();
  // The jogging drives stopped by themselves (a de-energised motor may still creep by a few
  // counts per second).
  EXPECT_LT(std::fabs(state("akd").velocity), 0.01 * 20) << diagnostics();
  EXPECT_LT(std::fabs(state("sd6").velocity), 0.01 * 3) << diagnostics();
  // The communication faults have no lasting cause: a reset clears them.
  for (const char* axis : {"akd", "nord", "sd6"}) {
    const auto r = send(axis, "fault_reset");
    EXPECT_EQ(r.outcome, Outcome::Completed) << axis << ": " << r.reason << diagnostics();
  }
  EXPECT_TRUE(wait_all("switch_on_disabled", 3s)) << diagnostics();
}

}  // namespace
}  // namespace drivegate::test
