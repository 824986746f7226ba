// The drives come up by themselves: no client action between starting the processes and every
// axis being operational and disabled.
#include <algorithm>

#include "tests/canopen_e2e/e2e_fixture.hpp"

namespace drivegate::test {
namespace {

TEST_F(CanopenE2e, EveryAxisComesUpByItselfDisabled) {
  ASSERT_TRUE(wait_all("switch_on_disabled", kStartUp)) << diagnostics();

  // Each axis went through the node life cycle the bus runs: booting, configuring, operational.
  for (const char* axis : {"akd", "nord", "sd6"}) {
    EXPECT_TRUE(wait_event(axis, "link_changed", "operational", 5s)) << axis << diagnostics();
    const auto s = state(axis);
    EXPECT_EQ(s.fault_code, 0U) << axis;
    EXPECT_FALSE(s.homed) << axis;
  }

  // The modes each device profile offers are what the gateway announces.
  const auto gateways = client_->gateways();
  ASSERT_EQ(gateways.size(), 1U);
  const auto modes = [&](const std::string& axis) {
    for (const auto& a : gateways.front().axes)
      if (a.name == axis) return a.modes;
    return std::vector<std::string>{};
  };
  const auto has = [](const std::vector<std::string>& list, const char* mode) {
    return std::find(list.begin(), list.end(), mode) != list.end();
  };
  for (const char* m : {"profile_position", "profile_velocity", "profile_torque", "homing", "interpolated_position",
                        "cyclic_position"})
    EXPECT_TRUE(has(modes("akd"), m)) << "akd " << m;
  EXPECT_FALSE(has(modes("akd"), "velocity"));
  for (const char* m : {"profile_position", "velocity", "profile_velocity", "profile_torque", "homing"})
    EXPECT_TRUE(has(modes("nord"), m)) << "nord " << m;
  EXPECT_FALSE(has(modes("nord"), "cyclic_position"));
  EXPECT_EQ(modes("sd6").size(), 3U);

  // The simulated drives agree: NMT operational, nothing enabled, no fault.
  std::string status;
  EXPECT_TRUE(sim_->wait_status([](const std::string& s) {
    for (int node : {1, 2, 3}) {
      const auto n = node_status(s, "can0", node);
      if (n.find("nmt=operational state=switch_on_disabled fault=0x0000") == std::string::npos) return false;
    }
    return true;
  }, 2s, status)) << status;

  // The bus is healthy, SYNC runs and the drives' frames arrive.
  ASSERT_TRUE(client_->wait_until([&] { return bus_status() && bus_status()->frames_received > 100; }, 5s));
  const auto bus = *bus_status();
  EXPECT_EQ(bus.type, "canopen");
  EXPECT_TRUE(bus.running);
  EXPECT_GT(bus.frames_sent, 0U);
}

}  // namespace
}  // namespace drivegate::test
