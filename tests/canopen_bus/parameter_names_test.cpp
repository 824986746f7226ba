// Objects named by clients, resolved by the gateway for an axis: EDS ParameterNames (with their
// type) and the SD6's parameter names; the types of objects named by index.
#include <gtest/gtest.h>

#include "config/loader.hpp"
#include "daemon/gateway.hpp"

namespace drivegate::canopen::test {
namespace {

// Axis 0: an AKD with the test EDS; axis 1: an SD6 without one.
config::Plan akd_with_eds_and_sd6() {
  const std::string yaml = std::string(R"(gateway: { name: names }
buses:
  - { name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim, bitrate: 1000000 } }
axes:
  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, unit: mm, mechanics: { feed: 5 },
      canopen: { eds: ")") + DRIVEGATE_TEST_EDS + R"(" } }
  - { name: sd6, bus: can0, address: 3, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 10000 } }
)";
  return config::load_plan_from_string(yaml, "names.yaml");
}

TEST(ParameterNames, EdsNamesAndVendorNamesResolvePerAxis) {
  const config::Plan plan = akd_with_eds_and_sd6();
  daemon::Gateway gw(plan);

  auto p = gw.lookup_parameter(0, "fbus.param05", 0, 0);  // case-insensitive
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x36E9);
  EXPECT_EQ(p.sub, 0);
  EXPECT_EQ(p.type, core::ParamType::U32);
  p = gw.lookup_parameter(0, "Target torque", 0, 0);
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x6071);
  EXPECT_EQ(p.type, core::ParamType::I16);
  EXPECT_EQ(p.type_source, "the EDS");
  p = gw.lookup_parameter(0, "A83", 0, 0);  // the AKD has no parameter naming
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.error.find("in its EDS"), std::string::npos) << p.error;

  p = gw.lookup_parameter(1, "A83", 0, 0);
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x2053);
  EXPECT_EQ(p.type, core::ParamType::Unknown);  // no EDS, not in the profile: the request names it
  p = gw.lookup_parameter(1, "E200[0]", 0, 0);  // SD6 TV-6
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.index, 0x28C8);
  p = gw.lookup_parameter(1, "A540", 0, 0);
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.error.find("A540"), std::string::npos) << p.error;
}

// Without a name the object is index:sub, typed by the EDS, then the device profile (its PDO maps
// and start-up writes), then CiA 301/402; anything else stays unknown.
TEST(ParameterNames, TypesFromEdsProfileAndStandards) {
  const config::Plan plan = akd_with_eds_and_sd6();
  daemon::Gateway gw(plan);
  struct Case {
    std::size_t axis;
    std::uint16_t index;
    std::uint8_t sub;
    core::ParamType type;
    const char* source;
  } cases[] = {
      {1, 0x1008, 0, core::ParamType::VisibleString, "CiA 301"},
      {1, 0x1018, 2, core::ParamType::U32, "CiA 301"},
      {1, 0x1400, 2, core::ParamType::U8, "CiA 301"},
      {1, 0x1800, 3, core::ParamType::U16, "CiA 301"},
      {1, 0x6064, 0, core::ParamType::I32, "device profile stoeber-sd6"},  // its TPDO 1 maps it
      {1, 0x6098, 0, core::ParamType::I8, "CiA 402"},
      {1, 0x2053, 0, core::ParamType::Unknown, ""},
      {0, 0x6071, 0, core::ParamType::I16, "the EDS"},
  };
  for (const auto& c : cases) {
    const auto p = gw.lookup_parameter(c.axis, "", c.index, c.sub);
    ASSERT_TRUE(p.ok) << p.error;
    EXPECT_EQ(p.index, c.index);
    EXPECT_EQ(p.type, c.type) << std::hex << c.index << ":" << int(c.sub);
    EXPECT_EQ(p.type_source, c.source) << std::hex << c.index << ":" << int(c.sub);
  }
}

// A bus type without parameter names of its own (sim): objects by index:sub, typed by the standards.
TEST(ParameterNames, ABusTypeWithoutNamesTakesIndexAndSub) {
  const config::Plan plan = config::load_plan_from_string(R"(gateway: { name: names }
buses:
  - { name: sim0, type: sim, cycle_time: 1ms }
axes:
  - { name: x, bus: sim0, address: 1, device: sim-servo, mechanics: { encoder_counts_per_rev: 4096 } }
)",
                                                          "names.yaml");
  daemon::Gateway gw(plan);
  auto p = gw.lookup_parameter(0, "", 0x6064, 0);
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.type, core::ParamType::I32);
  EXPECT_EQ(p.type_source, "CiA 402");
  p = gw.lookup_parameter(0, "Position actual value", 0, 0);
  EXPECT_FALSE(p.ok);
  EXPECT_EQ(p.error, "axis 'x' has no object named 'Position actual value' (give the axis an EDS file to use names, "
                     "or use INDEX:SUB)");
}

}  // namespace
}  // namespace drivegate::canopen::test
