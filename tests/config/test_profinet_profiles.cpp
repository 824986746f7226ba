// The `profidrive:` section of device profiles (config/profinet/device_section.cpp): the AKD
// PROFINET profile as the digest describes it, and what the reader refuses.
#include <gtest/gtest.h>

#include "config/device_profile.hpp"
#include "config/profinet/plan.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config::test {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

TEST(ProfinetProfiles, KollmorgenAkdProfinetIsTheDigestsDrive) {
  const DeviceProfile p = load_device_profile(fs::path{DRIVEGATE_DEVICE_DIR_SOURCE} / "kollmorgen-akd-profinet.yaml");
  ASSERT_TRUE(p.has_section<ProfidriveDeviceSpec>());
  const auto& s = p.section<ProfidriveDeviceSpec>();
  EXPECT_EQ(s.single_turn_bits, 16U);                 // §17.2
  EXPECT_DOUBLE_EQ(s.acc_full_scale_rpm_per_s, 50e6);  // §17.3
  EXPECT_FALSE(s.peak_current_a.has_value());
  EXPECT_EQ(s.telegrams, (std::vector<std::uint16_t>{0, 1, 7, 9, 350, 351, 352, 353, 400}));  // §4.3
  EXPECT_EQ(s.min_update_time, 16ms);                                                        // §2
  EXPECT_EQ(s.vendor_id, 0x0118);  // [sim]: the simulated AKD's DCP identity (the digest has none, §4.1)
  EXPECT_EQ(s.device_id, 0x0501);
  EXPECT_TRUE(s.quirks.at("control_by_plc_bit10"));
  EXPECT_TRUE(p.modes.contains(core::Mode::TraversingBlock));
  EXPECT_FALSE(p.modes.contains(core::Mode::ProfileTorque));
  EXPECT_EQ(p.homing_methods.front(), 0);  // the default method: what every telegram takes
  EXPECT_EQ(p.fault_texts.at(702), "Fieldbus communication lost");
  EXPECT_TRUE(p.cyclic_objects.empty());  // no CiA 402 image
}

class ProfinetProfileErrors : public TempDir {
 protected:
  std::string errors(const std::string& body) const {
    const auto file = write("pd.yaml", "name: pd\nvendor: test\n" + body);
    try {
      (void)load_device_profile(file);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "(loaded without error)";
  }
};

const std::string kUnits = R"(units:
  position: { per_rev: 65536 }
  velocity: { per_rps: 10737418.24 }
  acceleration: { per_rps2: 0.0786432 }
)";

TEST_F(ProfinetProfileErrors, AValidSectionLoads) {
  EXPECT_EQ(errors("modes: [pv]\n" + kUnits + "profidrive: { single_turn_bits: 16, acc_full_scale_rpm_per_s: 50e6, "
                                               "telegrams: [1], min_update_time: 4ms }\n"),
            "(loaded without error)");
}

TEST_F(ProfinetProfileErrors, TheUnitsMustBeTheNormalisations) {
  const std::string e = errors("modes: [pp]\nunits:\n  position: { per_rev: counts }\n  velocity: { per_rps: 60000 }\n"
                               "  acceleration: { per_rps2: 0.0786432 }\n"
                               "profidrive: { single_turn_bits: 20, acc_full_scale_rpm_per_s: 25e6, telegrams: [9], "
                               "min_update_time: 16ms }\n");
  EXPECT_REPORTED(e, "profidrive.single_turn_bits: needs units.position of 1048576 per motor rev (2^single_turn_bits "
                     "counts, PNU 1002), got a unit relative to another");
  EXPECT_REPORTED(e, "profidrive.single_turn_bits: needs units.velocity of 10737418.24 per motor rev/s (2^31 = 12000 rpm), got 60000");
  EXPECT_REPORTED(e, "profidrive.acc_full_scale_rpm_per_s: needs units.acceleration of 0.1572864 per motor rev/s^2 (MDI_ACC "
                     "2^16 = acc_full_scale_rpm_per_s), got 0.0786432");
}

TEST_F(ProfinetProfileErrors, TelegramsModesAndQuirksAreChecked) {
  const std::string e = errors("modes: [pp, cst]\n" + kUnits +
                               "profidrive: { single_turn_bits: 16, acc_full_scale_rpm_per_s: 50e6, telegrams: [1, 2, 1], "
                               "min_update_time: 16ms, quirks: { bit10: true } }\n");
  EXPECT_REPORTED(e, "modes: the PROFIdrive master drives pp, pv, hm and tb only, got cst");
  EXPECT_REPORTED(e, "profidrive.telegrams[1]: must be a telegram the PROFIdrive profile knows (0, 1, 7, 9, 350, 351, 352, "
                     "353, 400), got 2");
  EXPECT_REPORTED(e, "profidrive.telegrams[2]: telegram 1 is listed twice");
  EXPECT_REPORTED(e, "profidrive.quirks.bit10: unknown field");
  EXPECT_REPORTED(errors("modes: [pv]\n" + kUnits + "profidrive: { single_turn_bits: 16, acc_full_scale_rpm_per_s: 50e6, "
                                                    "telegrams: [1], min_update_time: 4ms, vendor_id: 0x10000 }\n"),
                  "profidrive.vendor_id: must be a PROFINET VendorID (0..0xFFFF)");
  EXPECT_REPORTED(errors("modes: [pv]\n" + kUnits + "profidrive: { single_turn_bits: 16, acc_full_scale_rpm_per_s: 50e6, "
                                                    "telegrams: [1], min_update_time: 4ms, device_id: 7 }\n"),
                  "profidrive.device_id: give vendor_id and device_id together");
  EXPECT_REPORTED(errors("modes: [pv]\n" + kUnits + "profidrive: { single_turn_bits: 16 }\n"),
                  "profidrive.telegrams: missing");
}

}  // namespace
}  // namespace drivegate::config::test
