#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "config/device_profile.hpp"

namespace drivegate::config {
namespace {

namespace fs = std::filesystem;

TEST(DeviceProfiles, EveryProfileInTheTreeLoads) {
  std::size_t count = 0;
  for (const auto& entry : fs::directory_iterator(DRIVEGATE_DEVICE_DIR_SOURCE)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const DeviceProfile p = load_device_profile(entry.path());
    EXPECT_EQ(p.name, entry.path().stem().string());
    EXPECT_FALSE(p.modes.empty());
    EXPECT_FALSE(p.vendor.empty());
    ++count;
  }
  EXPECT_GE(count, 2U);
}

TEST(DeviceProfiles, GenericProfileContent) {
  const DeviceProfile p = load_device_profile(fs::path{DRIVEGATE_DEVICE_DIR_SOURCE} / "generic-cia402.yaml");
  for (const auto m : {core::Mode::ProfilePosition, core::Mode::ProfileVelocity, core::Mode::ProfileTorque,
                       core::Mode::Homing, core::Mode::InterpolatedPosition, core::Mode::CyclicPosition,
                       core::Mode::CyclicVelocity, core::Mode::CyclicTorque})
    EXPECT_TRUE(p.modes.contains(m));
  EXPECT_FALSE(p.modes.contains(core::Mode::Velocity));
  EXPECT_EQ(p.homing_methods.size(), 36U);
  EXPECT_EQ(std::count(p.homing_methods.begin(), p.homing_methods.end(), 36), 0);
  EXPECT_EQ(p.units.position_base, UnitBase::EncoderCounts);
  EXPECT_EQ(p.fault_texts.at(0x8611), "Following error");
  const core::NativeUnits n = p.units.resolve(4096);
  EXPECT_DOUBLE_EQ(n.position_per_rev, 4096.0);
  EXPECT_DOUBLE_EQ(n.velocity_per_rps, 4096.0);
  EXPECT_DOUBLE_EQ(n.acceleration_per_rps2, 4096.0);
  EXPECT_DOUBLE_EQ(n.torque_per_rated, 1000.0);
}

TEST(DeviceProfiles, FixedRatesResolve) {
  NativeUnitsSpec s;
  s.position_base = UnitBase::Fixed;
  s.position_per_rev = 1000;
  s.velocity_base = UnitBase::Fixed;
  s.velocity_per_rps = 60000;  // AKD: 1/1000 rpm (akd-canopen-part2-ds402.md §4.3)
  s.acceleration_base = UnitBase::Velocity;
  const core::NativeUnits n = s.resolve(131072);
  EXPECT_DOUBLE_EQ(n.position_per_rev, 1000.0);
  EXPECT_DOUBLE_EQ(n.velocity_per_rps, 60000.0);
  EXPECT_DOUBLE_EQ(n.acceleration_per_rps2, 60000.0);
}

// A profile written to a private temporary directory (tests run in parallel).
class BrokenProfile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("drivegate-devtest-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / (name + ".yaml");
    std::ofstream(p) << text;
    return p;
  }
  std::string errors_of(const fs::path& p) {
    try {
      load_device_profile(p);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "(loaded without error)";
  }
  fs::path dir_;
};

TEST_F(BrokenProfile, EveryProblemIsReportedWithItsPosition) {
  const fs::path p = write("bad-drive", R"(name: other-name
vendor: test
modes: [pp, warp]
units:
  position: { per_rev: lots }
  velocity: { unit: position_per_s, per_rps: 60 }
  acceleration: { unit: position_per_s2 }
homing_methods: [35, 300]
fault_texts: { 0x1000: ok, banana: no }
quirks: { no_sync_producr: true }
cyclic_objects: ["0x6040", "6041", "0x6099:300"]
colour: red
)");
  const std::string e = errors_of(p);
  const std::string f = p.string();
  EXPECT_NE(e.find(f + ":1:7: name: must match the file name \"bad-drive\""), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":3:13: modes[1]: must be a mode name"), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":5:24: units.position.per_rev: must be \"counts\""), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":6:13: units.velocity: give exactly one of unit"), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":8:22: homing_methods[1]: must be an integer in -128..127, got \"300\""), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":9:28: fault_texts.banana: fault codes must be integers"), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":10:11: quirks.no_sync_producr: unknown field, did you mean \"no_sync_producer\"?"),
            std::string::npos) << e;
  EXPECT_NE(e.find(f + ":11:28: cyclic_objects[1]: must be an object as \"0x6040\""), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":11:36: cyclic_objects[2]:"), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":12:1: colour: unknown field"), std::string::npos) << e;
}

TEST_F(BrokenProfile, CyclicModesNeedTheirTargetInTheCyclicImage) {
  const fs::path p = write("thin-drive", R"(name: thin-drive
vendor: test
modes: [pp, ip, csv]
units: { position: { per_rev: counts }, velocity: { unit: position_per_s }, acceleration: { unit: position_per_s2 } }
cyclic_objects: ["0x6040", "0x6041", "0x607A"]
)");
  const std::string e = errors_of(p);
  const std::string f = p.string();
  EXPECT_NE(e.find(f + ":5:17: cyclic_objects: must include 0x60C1:1 (interpolation data record) for mode ip"),
            std::string::npos) << e;
  EXPECT_NE(e.find("must include 0x60FF (target velocity) for mode csv"), std::string::npos) << e;
  EXPECT_EQ(e.find("0x6040 (controlword)"), std::string::npos) << e;
}

TEST_F(BrokenProfile, MissingRequiredSections) {
  const fs::path p = write("empty-drive", "name: empty-drive\n");
  const std::string e = errors_of(p);
  const std::string f = p.string();
  EXPECT_NE(e.find(f + ":1:1: vendor: missing required field"), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":1:1: modes: missing required field"), std::string::npos) << e;
  EXPECT_NE(e.find(f + ":1:1: units: missing required field"), std::string::npos) << e;
  EXPECT_EQ(e.find("units.position"), std::string::npos) << "absence reported once: " << e;
}

TEST_F(BrokenProfile, UnreadableFile) {
  const std::string e = errors_of(dir_ / "nope.yaml");
  EXPECT_NE(e.find("nope.yaml: cannot open file"), std::string::npos) << e;
}

}  // namespace
}  // namespace drivegate::config
