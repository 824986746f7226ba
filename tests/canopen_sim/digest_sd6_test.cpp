// The SD6 persona and profile against the derived vectors D-10 and D-12 of stoeber-sd6-canopen.md
// §11.2: the DS6 names of the objects they read (A245, A246; A225[3] for 1600h:04) resolve with the
// profile's parameter naming, and the persona answers the reads it has on 605h/585h byte for byte.
#include <gtest/gtest.h>

#include "config/loader.hpp"
#include "config/canopen/parameter_names.hpp"
#include "tests/canopen_sim/sim_test_support.hpp"

namespace drivegate::canopen::sim::test {
namespace {

const char* kPlan = R"(gateway: { name: sd6-digest }
buses:
  - { name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim, bitrate: 1000000 } }
axes:
  - { name: sd6, bus: can0, address: 5, device: stoeber-sd6, mechanics: { encoder_counts_per_rev: 10000 } }
)";

TEST(Sd6DigestSim, DeviceNamesOfD10AndD12) {
  const config::Plan plan = config::load_plan_from_string(kPlan, "sd6-digest.yaml");
  const auto& naming = plan.buses.at(0).axes.at(0).device.section<config::CanopenDeviceSpec>().parameter_naming;
  ASSERT_TRUE(naming.has_value());
  EXPECT_EQ(config::parse_parameter_name("A245", *naming), (ObjectId{0x20F5, 0}));     // D-10
  EXPECT_EQ(config::parse_parameter_name("A246", *naming), (ObjectId{0x20F6, 0}));     // D-10
  EXPECT_EQ(config::parse_parameter_name("A225[3]", *naming), (ObjectId{0x20E1, 3}));  // D-12
  EXPECT_EQ(config::parse_parameter_name("A83", *naming), (ObjectId{0x2053, 0}));      // D-11
}

TEST(Sd6DigestSim, D10AndD12Reads) {
  Drive d(sd6(5));
  ASSERT_TRUE(is_frame(d.boot().at(0), 0x705, {0x00}));
  // D-10: A246, the NMT state in the DS6 numbering (4 = pre-operational, quirk 18), answered with
  // 42h like every small upload of this drive (D-1, D-2).
  auto r = d.sdo(SdoBytes{0x40, 0xF6, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00});
  EXPECT_TRUE(is_frame(r.frame, 0x585, {0x42, 0xF6, 0x20, 0x00, 0x04, 0x00, 0x00, 0x00}));
  // D-12: RxPDO1 mapping entry 4, empty in the profile's three-entry map of the six fixed ones.
  r = d.sdo(SdoBytes{0x40, 0x00, 0x16, 0x04, 0x00, 0x00, 0x00, 0x00});
  EXPECT_TRUE(is_frame(r.frame, 0x585, {0x42, 0x00, 0x16, 0x04, 0x00, 0x00, 0x00, 0x00}));
  r = d.sdo(SdoBytes{0x40, 0x00, 0x16, 0x03, 0x00, 0x00, 0x00, 0x00});  // entry 3 for contrast: 607Ah
  EXPECT_TRUE(is_frame(r.frame, 0x585, {0x42, 0x00, 0x16, 0x03, 0x20, 0x00, 0x7A, 0x60}));
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
