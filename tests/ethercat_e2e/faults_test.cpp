// Faults on the wire with the real binaries, injected through drivegate-sim's console: a slave
// that loses power, a cable cut behind a slave, and a gateway that is killed outright.
#include <gtest/gtest.h>
#include <signal.h>

#include <string>

#include "tests/ethercat_e2e/ecat_fixture.hpp"

namespace drivegate::test {
namespace {

class EthercatE2eFaults : public EthercatE2eUp {
 protected:
  // Both drives enabled, as in production when a fault hits.
  void enable_both() {
    ASSERT_NO_FATAL_FAILURE(enable("esr"));
    ASSERT_NO_FATAL_FAILURE(enable("gen"));
  }

  // While `lost` is gone: the ESR in front of it keeps cycling, enabled, in the gateway's view and
  // in the drive model's (no watchdog ran out on it); the frames keep coming back.
  void expect_esr_keeps_cycling() {
    const auto before = bus_status();
    ASSERT_TRUE(before);
    ASSERT_TRUE(client_->wait_until([&] {
      const auto b = bus_status();
      return b && b->frames_received > before->frames_received + 200;
    }, 5s)) << diagnostics();
    const auto esr = state("esr");
    EXPECT_EQ(esr.link, "operational") << diagnostics();
    EXPECT_EQ(esr.state, "operation_enabled") << diagnostics();
    const std::string d = sim("drive 1");
    EXPECT_EQ(field(d, "state"), "operation_enabled") << d;
    EXPECT_EQ(field(d, "error"), "0x0000") << d;
  }
};

// Slave 3 (the generic drive, last on the line) loses power: its axis goes lost, the ESR and the
// panel in front of it keep exchanging; with power back it is started again from scratch and
// comes back operational and disabled (never enabled by itself).
TEST_F(EthercatE2eFaults, SlavePowerLossAndReturn) {
  ASSERT_NO_FATAL_FAILURE(enable_both());
  ASSERT_EQ(sim("power-off 3"), "ok power-off ec0:3");
  ASSERT_TRUE(wait_link("gen", "lost", "", 5s)) << diagnostics();
  ASSERT_NO_FATAL_FAILURE(expect_esr_keeps_cycling());
  const auto p = panel();
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->valid) << diagnostics();
  EXPECT_EQ(state("gen").link, "lost");

  ASSERT_EQ(sim("power-on 3"), "ok power-on ec0:3");
  ASSERT_TRUE(wait_link("gen", "operational", "switch_on_disabled", 20s)) << diagnostics();
  std::string last;
  ASSERT_TRUE(wait_sim("status", [](const std::string& s) {
    return s.find("ec0:3 generic-cia402 station=0x1003 state=OP code=0x0000") != std::string::npos;
  }, 5s, last)) << last;
  EXPECT_EQ(field(sim("drive 3"), "state"), "switch_on_disabled");
  EXPECT_EQ(state("esr").state, "operation_enabled");
  // The drive is the line's DC reference clock: restarted, its ESC runs SYNC0 again (the drive
  // reaches OP in SYNC0 mode only with it) and the pulses go on.
  ASSERT_TRUE(wait_sim("drive 3", [](const std::string& d) {
    const std::string n = field(d, "sync0");
    return !n.empty() && n != "off" && std::stoull(n) > 100;
  }, 5s, last)) << last << diagnostics();
  // It works again: enabled on command.
  ASSERT_NO_FATAL_FAILURE(enable("gen"));
}

// The cable cut behind slave 1: the panel and the generic drive vanish (axis lost, inputs stale),
// the ESR keeps cycling. Cut off from the master, the generic drive's SM watchdog runs out and it
// faults through 6007h (8100h), as a real drive would. Mended, both are started again: the drive
// comes back operational with that fault and its power stage off (the gateway does not reset a
// fault by itself), a fault reset takes it to disabled, and it enables again; the panel's inputs
// are valid again.
TEST_F(EthercatE2eFaults, CableBreakAndMend) {
  ASSERT_NO_FATAL_FAILURE(enable_both());
  ASSERT_EQ(sim("break-after 1"), "ok break-after ec0:1");
  ASSERT_TRUE(wait_link("gen", "lost", "", 5s)) << diagnostics();
  ASSERT_TRUE(client_->wait_until([&] {
    const auto p = panel();
    return p && !p->valid;
  }, 5s)) << diagnostics();
  ASSERT_NO_FATAL_FAILURE(expect_esr_keeps_cycling());
  std::string last;
  ASSERT_TRUE(wait_sim("drive 3", [](const std::string& d) { return field(d, "state") == "fault"; }, 5s, last))
      << last << diagnostics();
  EXPECT_EQ(field(last, "error"), "0x8100") << last;

  ASSERT_EQ(sim("mend"), "ok mend ec0");
  ASSERT_TRUE(wait_link("gen", "operational", "fault", 20s)) << diagnostics();
  EXPECT_EQ(state("gen").fault_code, 0x8100U) << diagnostics();
  ASSERT_TRUE(client_->wait_until([&] {
    const auto p = panel();
    return p && p->valid;
  }, 10s)) << diagnostics();
  ASSERT_TRUE(wait_sim("status", [](const std::string& s) {
    return s.find("ec0:2 generic-io station=0x1002 state=OP code=0x0000") != std::string::npos &&
           s.find("ec0:3 generic-cia402 station=0x1003 state=OP code=0x0000") != std::string::npos;
  }, 5s, last)) << last;
  EXPECT_EQ(state("esr").state, "operation_enabled");
  const auto reset = send("gen", "fault_reset");
  ASSERT_EQ(reset.outcome, client::Outcome::Completed) << reset.reason << diagnostics();
  ASSERT_TRUE(wait_link("gen", "operational", "switch_on_disabled", 5s)) << diagnostics();
  ASSERT_NO_FATAL_FAILURE(enable("gen"));
}

// drivegated killed with SIGKILL (no safe stop, no SAFE-OP): the process data stops, each drive's
// SM watchdog runs out, the ESC leaves OP with AL status code 001Bh and the drive faults through
// its 6007h reaction (1: fault, EMCY 8100h; the ESR's 6007h = 1 is the gateway's start-up write).
// A gateway started again recovers them.
TEST_F(EthercatE2eFaults, KilledGatewayFaultsTheDrivesThroughTheirWatchdog) {
  ASSERT_NO_FATAL_FAILURE(enable_both());
  const auto rc = daemon_->terminate(SIGKILL, 5s);
  ASSERT_TRUE(rc.has_value());
  EXPECT_EQ(*rc, 128 + SIGKILL);
  std::string last;
  for (const int k : {1, 3}) {
    ASSERT_TRUE(wait_sim("drive " + std::to_string(k), [](const std::string& d) {
      return field(d, "state") == "fault";
    }, 5s, last)) << last << diagnostics();
    EXPECT_EQ(field(last, "error"), "0x8100") << last;
  }
  ASSERT_TRUE(wait_sim("status", [](const std::string& s) {
    return s.find("ec0:1 esr-triodrive station=0x1001 state=SAFE-OP+ERR code=0x001B") != std::string::npos &&
           s.find("ec0:2 generic-io station=0x1002 state=SAFE-OP+ERR code=0x001B") != std::string::npos &&
           s.find("ec0:3 generic-cia402 station=0x1003 state=SAFE-OP+ERR code=0x001B") != std::string::npos;
  }, 5s, last)) << last;

  // A new gateway takes the line from there (the slaves in SAFE-OP with the error set): the drives
  // come back operational in their fault, are reset and enable again.
  ASSERT_NO_FATAL_FAILURE(start_gateway());
  for (const char* axis : {"esr", "gen"}) {
    ASSERT_TRUE(wait_link(axis, "operational", "fault", kStartUp)) << axis << diagnostics();
    EXPECT_EQ(state(axis).fault_code, 0x8100U) << axis;
    const auto reset = send(axis, "fault_reset");
    ASSERT_EQ(reset.outcome, client::Outcome::Completed) << axis << ": " << reset.reason << diagnostics();
    ASSERT_NO_FATAL_FAILURE(enable(axis));
  }
  EXPECT_NE(sim("status").find("ec0:2 generic-io station=0x1002 state=OP code=0x0000"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::test
