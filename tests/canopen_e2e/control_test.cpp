// Control of real CANopen axes (drivegated and drivegate-sim on udp-multicast): every way out of
// the daemon stops and disables them, writes to what the gateway configured are refused, and a
// drive that stops following its controlword is stopped over SDO and brought back disabled.
#include <cmath>
#include <csignal>

#include "tests/canopen_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

class CanopenE2eControl : public CanopenE2eUp {
 protected:
  // Every drive enabled and on a long move.
  void enable_and_move_all() {
    for (const char* axis : {"akd", "nord", "sd6"}) {
      const auto en = send(axis, "enable");
      ASSERT_EQ(en.outcome, client::Outcome::Completed) << axis << ": " << en.reason << diagnostics();
      auto mv = request(axis, "move");
      mv.position = 200;
      mv.velocity = 2;
      const auto r = start(mv);
      ASSERT_EQ(r.outcome, client::Outcome::Accepted) << axis << ": " << r.reason << diagnostics();
    }
    for (const char* axis : {"akd", "nord", "sd6"})
      ASSERT_TRUE(wait_axis(axis, [](const client::AxisState& s) { return std::fabs(s.velocity) > 1; }, 5s))
          << axis << diagnostics();
  }

  // What the simulated drives say about themselves, not what the gateway published.
  void expect_drives_disabled() {
    const std::string status = sim_->command("status");
    for (const char* node : {":1 ", ":2 ", ":3 "}) {
      const auto at = status.find(node);
      ASSERT_NE(at, std::string::npos) << status;
      const auto end = status.find(';', at);
      EXPECT_NE(status.substr(at, end - at).find("state=switch_on_disabled"), std::string::npos) << status;
    }
  }
};

// SIGTERM with every CANopen drive enabled and moving: exit 0, every drive disabled at the drive.
TEST_F(CanopenE2eControl, SigtermStopsAndDisablesEveryMovingDrive) {
  ASSERT_NO_FATAL_FAILURE(enable_and_move_all());
  const auto rc = daemon_->terminate(SIGTERM, 20s);
  ASSERT_TRUE(rc.has_value()) << diagnostics();
  EXPECT_EQ(*rc, 0) << diagnostics();
  EXPECT_NE(daemon_->log().find("3 axes quick-stopped, 3 disabled"), std::string::npos) << diagnostics();
  expect_drives_disabled();
}

// `param set akd 1400:1 0x80000201` is refused; when the mapping is switched off behind the
// gateway's back anyway (the drive's service interface), the next stop finds the drive not
// following: a control_lost event, a stop over SDO, reconfiguration, the axis back disabled. And a
// SIGTERM while a drive is out of control still ends with every drive disabled.
TEST_F(CanopenE2eControl, ADriveThatStopsFollowingIsStoppedAndReconfigured) {
  client::ParamRequest p;
  p.axis = "akd";
  p.write = true;
  p.index = 0x1400;
  p.subindex = 1;
  p.value = "0x80000201";
  const auto refused = client_->param(p, 5s);
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.error.find("owned by the CANopen bus (RPDO communication parameter)"), std::string::npos)
      << refused.error;

  ASSERT_NO_FATAL_FAILURE(enable_and_move_all());
  ASSERT_EQ(sim_->command("service-write 1 0x1400:1 0x80000201 4"), "ok service-write node 1");
  const auto stop = send("akd", "quick_stop");
  EXPECT_EQ(stop.outcome, client::Outcome::Failed) << stop.reason;
  EXPECT_NE(stop.reason.find("stopped following"), std::string::npos) << stop.reason;
  EXPECT_TRUE(wait_event("akd", "control_lost", "does not follow its controlword", 5s)) << diagnostics();
  ASSERT_TRUE(wait_axis("akd", [](const client::AxisState& s) {
    return s.link == "operational" && s.state == "switch_on_disabled";
  }, 15s)) << diagnostics();

  // Once more, and this time SIGTERM arrives while the drive runs out of the gateway's control:
  // the shutdown waits for the stop over SDO before it releases the bus.
  ASSERT_EQ(send("akd", "enable").outcome, client::Outcome::Completed) << diagnostics();
  auto mv = request("akd", "move");
  mv.position = -50;
  mv.velocity = 2;
  ASSERT_EQ(start(mv).outcome, client::Outcome::Accepted) << diagnostics();
  ASSERT_TRUE(wait_axis("akd", [](const client::AxisState& s) { return std::fabs(s.velocity) > 1; }, 5s))
      << diagnostics();
  ASSERT_EQ(sim_->command("service-write 1 0x1400:1 0x80000201 4"), "ok service-write node 1");
  const auto rc = daemon_->terminate(SIGTERM, 20s);
  ASSERT_TRUE(rc.has_value()) << diagnostics();
  EXPECT_EQ(*rc, 0) << diagnostics();
  expect_drives_disabled();
  const std::string log = daemon_->log();
  std::size_t losses = 0;
  for (auto at = log.find("akd: control_lost"); at != std::string::npos; at = log.find("akd: control_lost", at + 1))
    ++losses;
  EXPECT_EQ(losses, 2u) << log;
}

}  // namespace
}  // namespace drivegate::test
