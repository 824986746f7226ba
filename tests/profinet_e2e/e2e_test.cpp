// The PROFINET adapter end to end with the real binaries (the set-up: e2e_fixture.hpp). The gateway
// finds the stations by name, gives them their addresses, connects them and runs the PROFIdrive
// axes; the client enables one and runs it in speed mode; a power loss from the simulator's console
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
