// The PROFINET adapter end to end with the real binaries (the set-up: e2e_fixture.hpp). The gateway
// finds the stations by name, gives them their addresses, connects them and runs the PROFIdrive
// axes; the client enables one and runs it in speed mode, and homes, moves in MDI, runs a
// traversing block and jogs the other; a power loss from the simulator's console
// is a lost link and a reconnect with the axis disabled, the other drive untouched; records and
// I&M0 over the parameter topic and the link detail.
#include <gtest/gtest.h>

#include <cmath>

#include "core/device_identity.hpp"
#include "core/param_value.hpp"
#include "tests/profinet_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

TEST_F(ProfinetE2e, AnAkdIsEnabledAndRunsInSpeedMode) {
  const auto en = send("x", "enable");
  ASSERT_EQ(en.outcome, client::Outcome::Completed) << en.reason << diagnostics();
  auto mode = request("x", "set_mode");
  mode.mode = "pv";
  ASSERT_EQ(send(mode).outcome, client::Outcome::Completed) << diagnostics();
  auto v = request("x", "velocity");
  v.velocity = 2.0;
  const auto r = start(v);
  ASSERT_NE(r.outcome, client::Outcome::Failed) << r.reason << diagnostics();
  EXPECT_TRUE(wait_axis("x", [](const client::AxisState& s) { return std::fabs(s.velocity - 2.0) < 0.1; }, 5s))
      << diagnostics();
  EXPECT_EQ(state("y").state, "switch_on_disabled");
  const auto off = send("x", "disable");
  EXPECT_EQ(off.outcome, client::Outcome::Completed) << off.reason << diagnostics();
}

// Application class 3 on the AKD with telegram 352 at its 16 ms update: homed (STW1 bit 11), moved
// in MDI out and back, a traversing block stored through the MT.* PNUs and run (program mode),
// jogged (real-time jog, STW1 bit 12) and stopped, then disabled to S1.
TEST_F(ProfinetE2e, AnAkdIsHomedMovedInMdiRunsABlockAndJogs) {
  const auto en = send("y", "enable");
  ASSERT_EQ(en.outcome, client::Outcome::Completed) << en.reason << diagnostics();
  const auto home = send("y", "home");
  ASSERT_EQ(home.outcome, client::Outcome::Completed) << home.reason << diagnostics();
  const auto at = [&](double target) {
    return wait_axis("y", [target](const client::AxisState& s) { return std::fabs(s.position - target) < 1e-3; }, 5s);
  };
  for (const double target : {3.0, 0.0}) {
    auto mv = request("y", "move");
    mv.position = target;  // rev
    mv.velocity = 2.0;
    mv.acceleration = 20.0;
    mv.deceleration = 20.0;
    const auto r = send(mv);
    ASSERT_EQ(r.outcome, client::Outcome::Completed) << target << ": " << r.reason << diagnostics();
    EXPECT_TRUE(at(target)) << target << diagnostics();
  }

  // Task 1: absolute to 2 rev at 375 rpm, 8 steps of PNU 1008 (6100 rpm/s) both ways [§16.1].
  const auto write = [&](const std::string& pnu, const std::string& type, const std::string& value) {
    client::ParamRequest q;
    q.axis = "y";
    q.name = pnu;
    q.write = true;
    q.type = type;
    q.value = value;
    const auto r = client_->param(q, 5s);
    EXPECT_TRUE(r.ok) << pnu << ": " << r.error;
  };
  write("p2274", "u8", "1");            // MT.NUM
  write("p2275", "i32", "131072");      // MT.P, counts
  write("p2283", "u32", "0x08000000");  // MT.V_32, 2^32 = 12000 rpm
  write("p2263", "u32", "8");           // MT.ACC
  write("p2268", "u32", "8");           // MT.DEC
  write("p2266", "u32", "1");           // MT.CNTL: absolute
  write("p2277", "u8", "0");            // MT.SET
  auto block = request("y", "run_block");
  block.block = 1;
  const auto b = send(block);
  ASSERT_EQ(b.outcome, client::Outcome::Completed) << b.reason << diagnostics();
  EXPECT_TRUE(at(2.0)) << diagnostics();

  auto jog = request("y", "velocity");
  jog.velocity = -1.5;  // rev/s
  jog.acceleration = 20.0;
  jog.deceleration = 20.0;
  const auto j = start(jog);
  ASSERT_NE(j.outcome, client::Outcome::Failed) << j.reason << diagnostics();
  // A jog lasts while its set-point is kept alive (the axis' command timeout, 500 ms), as
  // drivegate-demo does.
  bool jogging = false;
  for (int i = 0; i < 100 && !jogging; ++i) {
    ASSERT_EQ(client_->stream_setpoint("y", {}, 0, jog.velocity, 0), "");
    jogging = wait_axis("y", [](const client::AxisState& s) { return std::fabs(s.velocity + 1.5) < 0.1; }, 50ms);
  }
  EXPECT_TRUE(jogging) << diagnostics();
  const auto stop = send("y", "stop");
  ASSERT_EQ(stop.outcome, client::Outcome::Completed) << stop.reason << diagnostics();
  EXPECT_LT(state("y").position, 2.0);
  EXPECT_EQ(state("y").state, "operation_enabled");

  const auto off = send("y", "disable");
  ASSERT_EQ(off.outcome, client::Outcome::Completed) << off.reason << diagnostics();
  // The state topic follows the reply within a status period.
  EXPECT_TRUE(wait_axis("y", [](const client::AxisState& s) { return s.state == "switch_on_disabled"; }, 1s))
      << diagnostics();
}

TEST_F(ProfinetE2e, PowerLossIsALostLinkAndTheDriveComesBackDisabled) {
  const auto en = send("x", "enable");
  ASSERT_EQ(en.outcome, client::Outcome::Completed) << en.reason << diagnostics();
  ASSERT_EQ(sim_->command("power-off akd-x", 5s).substr(0, 2), "ok") << diagnostics();
  ASSERT_TRUE(wait_axis("x", [](const client::AxisState& s) { return s.link == "lost"; }, 10s)) << diagnostics();
  EXPECT_EQ(state("y").link, "operational");
  ASSERT_EQ(sim_->command("power-on akd-x", 5s).substr(0, 2), "ok") << diagnostics();
  // Found again by name, its address given again (it lost the temporary one), a new AR.
  ASSERT_TRUE(wait_axis("x", [](const client::AxisState& s) { return s.link == "operational" && s.state == "switch_on_disabled"; },
                        20s))
      << diagnostics();
  EXPECT_EQ(state("y").link, "operational");
}

// Records over the DDS parameter topic: I&M0 of a drive's DAP as bytes, I&M1 written and read
// back, I&M0 of the IO device by its name, an unknown slot refused in the device's words; and the
// drive's I&M0 read at connect in the axis' link detail, as `drivegatectl list` reads it.
TEST_F(ProfinetE2e, RecordsGoOverTheParameterTopic) {
  const auto param = [&](const std::string& target, const std::string& address, bool write = false,
                         const std::string& value = {}) {
    client::ParamRequest q;
    q.axis = target;
    q.name = address;
    q.write = write;
    q.value = value;
    return client_->param(q, 5s);
  };
  // A PNU through the PROFIdrive parameter channel (record 47): PNU 964 subindex 0, the
  // manufacturer ID of the device identification, and a CANopen address refused in words.
  auto r = param("x", "p964[0]");
  ASSERT_TRUE(r.ok) << r.error << diagnostics();
  EXPECT_EQ(r.data.size(), 2U);  // a word (format 0x42)
  r = param("x", "6041h:00");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("takes parameters by PNU"), std::string::npos) << r.error;

  r = param("x", "rec:0:1:0xAFF0");
  ASSERT_TRUE(r.ok) << r.error << diagnostics();
  EXPECT_EQ(r.type, core::ParamType::OctetString);
  ASSERT_EQ(r.data.size(), 60U);
  EXPECT_EQ(std::string(r.data.begin() + 8, r.data.begin() + 28), "AKD-P00306-NBPN-0000");
  const std::string tags = "00 21 00 38 01 00 " + core::hex_bytes(std::vector<std::uint8_t>(54, 'T'));
  r = param("y", "rec:0:1:0xAFF1", true, tags);
  ASSERT_TRUE(r.ok) << r.error << diagnostics();
  r = param("y", "rec:0:1:0xAFF1");
  ASSERT_TRUE(r.ok) << r.error << diagnostics();
  EXPECT_EQ(core::hex_bytes(r.data), tags);
  r = param("valves", "rec:0:1:0xAFF0");
  ASSERT_TRUE(r.ok) << r.error << diagnostics();
  EXPECT_EQ(r.data.size(), 60U);
  r = param("x", "rec:7:1:0xAFF0");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("invalid slot"), std::string::npos) << r.error;
  EXPECT_EQ(r.error_code, 0xDE80B200U);

  ASSERT_TRUE(client_->wait_until([&] {
    const auto l = client_->link("x");
    return l && core::identity_in_link_detail(l->detail).has_value();
  }, 5s)) << diagnostics();
  EXPECT_EQ(core::identity_in_link_detail(client_->link("x")->detail)->order_id, "AKD-P00306-NBPN-0000");
}

}  // namespace
}  // namespace drivegate::test
