// Objects named by clients, resolved by the gateway for an axis: EDS ParameterNames (with their
// size and sign) and the SD6's parameter names.
#include <gtest/gtest.h>

#include "config/loader.hpp"
#include "daemon/gateway.hpp"

namespace drivegate::canopen::test {
namespace {

TEST(ParameterNames, EdsNamesAndVendorNamesResolvePerAxis) {
  const std::string yaml = std::string(R"(gateway: { name: names }
buses:
  - { name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim, bitrate: 1000000 } }
axes:
  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, unit: mm, mechanics: { feed: 5 },
      canopen: { eds: ")") + DRIVEGATE_TEST_EDS + R"(" } }
  - { name: sd6, bus: can0, address: 3, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 10000 } }
)";
  const config::Plan plan = config::load_plan_from_string(yaml, "names.yaml");
  daemon::Gateway gw(plan);

  auto p = gw.lookup_parameter(0, "fbus.param05");  // case-insensitive
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x36E9);
  EXPECT_EQ(p.sub, 0);
  EXPECT_EQ(p.size, 4);
  p = gw.lookup_parameter(0, "Target torque");
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x6071);
  EXPECT_EQ(p.size, 2);
  EXPECT_TRUE(p.is_signed);
  p = gw.lookup_parameter(0, "A83");  // the AKD has no parameter naming
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.error.find("in its EDS"), std::string::npos) << p.error;

  p = gw.lookup_parameter(1, "A83");
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x2053);
  EXPECT_EQ(p.size, 0);  // no EDS: the request's size applies
  p = gw.lookup_parameter(1, "E200[0]");  // SD6 TV-6
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x28C8);
  p = gw.lookup_parameter(1, "A540");
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.error.find("A540"), std::string::npos) << p.error;
}

}  // namespace
}  // namespace drivegate::canopen::test
