// Velocity, torque, interpolated and cyclic modes, mode selection and limit switches on the drive
// side [AKD digest §3.6, §5, §6, §8; nord §5.2-§5.4].
#include <gtest/gtest.h>

#include <cmath>

#include "tests/cia402_sim/drive_harness.hpp"

namespace drivegate::cia402::sim::test {
namespace {

constexpr std::uint16_t kReached = 0x0400;
constexpr std::uint16_t kLimit = 0x0800;
constexpr std::uint16_t kBit12 = 0x1000;

TEST(ModeSelection, DisplayFollowsInTheNextStep) {
  DriveHarness h;
  h.step();
  h.set(obj::kModesOfOperation, op_mode::kProfileVelocity);
  EXPECT_EQ(h.get(obj::kModesOfOperationDisplay), 0);
  h.step();
  EXPECT_EQ(h.get(obj::kModesOfOperationDisplay), op_mode::kProfileVelocity);
}

TEST(ModeSelection, UnsupportedModeIsRefused) {
  DriveModelConfig cfg;
  cfg.supported_modes = {1, 3, 4, 6, 7, 8};  // the AKD's set [AKD digest §3.6]
  DriveHarness h(cfg);
  EXPECT_EQ(h.drive.write_object(obj::kModesOfOperation.id, op_mode::kCyclicVelocity), 0x06090030U);
  EXPECT_EQ(h.drive.write_object(obj::kModesOfOperation.id, 5), 0x06090030U);
  EXPECT_EQ(h.drive.write_object(obj::kModesOfOperation.id, op_mode::kCyclicPosition), 0U);
  EXPECT_EQ(h.get(obj::kSupportedDriveModes), 0xEDU);  // bits 0, 2, 3, 5, 6, 7
}

TEST(ModeSelection, IdentityObjects) {
  DriveModelConfig cfg;
  cfg.identity = {0x6A, 0x1234, 0x00010002, 42};
  DriveHarness h(cfg);
  EXPECT_EQ(h.drive.read_object({0x1000, 0}).value, 0x00020192);
  EXPECT_EQ(h.drive.read_object({0x1018, 0}).value, 4);
  EXPECT_EQ(h.drive.read_object({0x1018, 1}).value, 0x6A);
  EXPECT_EQ(h.drive.read_object({0x1018, 2}).value, 0x1234);
  EXPECT_EQ(h.drive.read_object({0x1018, 3}).value, 0x00010002);
  EXPECT_EQ(h.drive.read_object({0x1018, 4}).value, 42);
  EXPECT_EQ(h.drive.write_object({0x1018, 1}, 1), 0x06010002U);
  EXPECT_EQ(h.drive.write_object({0x1018, 5}, 1), 0x06090011U);
  EXPECT_EQ(h.drive.write_object({0x2000, 0}, 1), 0x06020000U);
}

TEST(ProfileVelocity, RampsToTargetAndReportsVelocityReached) {
  DriveHarness h;
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kTargetVelocity, 100000);
  h.step();
  EXPECT_EQ(h.sw() & kReached, 0);
  const int steps = h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_GT(steps, 90);  // 10 rev/s at 100 rev/s^2: 100 ms
  EXPECT_LT(steps, 130);
  EXPECT_NEAR(static_cast<double>(h.get(obj::kVelocityActual)), 100000.0, 100.0);
  h.set(obj::kTargetVelocity, -50000);
  h.step();
  EXPECT_EQ(h.sw() & kReached, 0);
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_NEAR(h.drive.velocity(), -50000.0, 100.0);
}

TEST(ProfileVelocity, TargetAboveTheLimitIsClampedWithInternalLimit) {
  DriveHarness h;
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kMaxProfileVelocity, 30000);
  h.set(obj::kTargetVelocity, 100000);
  h.step(200);
  EXPECT_NEAR(h.drive.velocity(), 30000.0, 100.0);
  EXPECT_NE(h.sw() & kLimit, 0);
}

TEST(ProfileVelocity, HaltDeceleratesHoldsAndResumes) {
  DriveHarness h;
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kTargetVelocity, 100000);
  h.step(200);
  h.cw(0x010F);
  h.step();
  EXPECT_EQ(h.sw() & kReached, 0);  // stopping
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_LT(std::abs(h.drive.velocity()), 100.0);
  EXPECT_EQ(h.get(obj::kTargetVelocity), 100000);  // halt keeps the set-point
  const double held = h.drive.position();
  h.step(100);
  EXPECT_NEAR(h.drive.position(), held, 5.0);
  h.cw(0x000F);
  h.step(200);
  EXPECT_NEAR(h.drive.velocity(), 100000.0, 100.0);
}

TEST(VelocityMode, RunsOnlyWithRampBitsSet) {
  DriveHarness h;
  h.enable(op_mode::kVelocity);
  h.set(obj::kVlTargetVelocity, 600);  // rpm: 10 rev/s
  h.step(100);
  EXPECT_LT(std::abs(h.drive.velocity()), 1.0);  // 0x000F does not run vl
  h.cw(0x007F);
  // 6048h default: 1500 rpm per 1 s -> 600 rpm in 0.4 s.
  h.step(450);
  EXPECT_NEAR(static_cast<double>(h.get(obj::kVlVelocityActual)), 600.0, 2.0);
  EXPECT_NEAR(static_cast<double>(h.get(obj::kVlVelocityDemand)), 600.0, 0.5);
  EXPECT_NEAR(h.drive.velocity(), 100000.0, 200.0);
  h.cw(0x005F);  // bit 5 cleared: ramp output frozen
  h.set(obj::kVlTargetVelocity, 0);
  h.step(100);
  EXPECT_NEAR(static_cast<double>(h.get(obj::kVlVelocityDemand)), 600.0, 0.5);
  h.cw(0x003F);  // bit 6 cleared: reference 0, ramp down
  h.step(450);
  EXPECT_LT(std::abs(h.drive.velocity()), 100.0);
}

TEST(ProfileTorque, RampsTorqueAndAcceleratesTheLoad) {
  DriveHarness h;
  h.enable(op_mode::kProfileTorque);
  h.set(obj::kTargetTorque, 100);  // 10 % of rated
  h.step(5);
  EXPECT_NEAR(static_cast<double>(h.get(obj::kTorqueActual)), 50.0, 1.0);  // 6087h 10000 per mille/s
  EXPECT_EQ(h.sw() & kReached, 0);
  h.step(10);
  EXPECT_EQ(h.get(obj::kTorqueActual), 100);
  EXPECT_NE(h.sw() & kReached, 0);
  const double v1 = h.drive.velocity();
  h.step(100);
  EXPECT_GT(h.drive.velocity(), v1 + 50000.0);  // 100 rev/s^2 less friction
  h.step(3000);
  EXPECT_LE(h.drive.velocity(), 500000.0 + 1e-6);  // motor speed limit
}

TEST(ProfileTorque, MaxTorqueClampsWithInternalLimit) {
  DriveHarness h;
  h.enable(op_mode::kProfileTorque);
  h.set(obj::kMaxTorque, 200);
  h.set(obj::kTargetTorque, -500);
  h.step(50);
  EXPECT_EQ(h.get(obj::kTorqueActual), -200);
  EXPECT_NE(h.sw() & kLimit, 0);
  EXPECT_LT(h.drive.velocity(), 0.0);
}

TEST(InterpolatedPosition, FollowsDataRecordWhileEnabled) {
  DriveHarness h;
  h.enable(op_mode::kInterpolatedPosition);
  EXPECT_EQ(h.sw() & kBit12, 0);
  h.set(obj::kIpDataRecord, 0);
  h.cw(0x001F);
  h.step();
  EXPECT_NE(h.sw() & kBit12, 0);  // ip mode active
  for (int i = 1; i <= 300; ++i) {
    h.set(obj::kIpDataRecord, i * 50);  // 50000 units/s
    h.step();
  }
  EXPECT_EQ(h.get(obj::kPositionDemand), 15000);
  EXPECT_NEAR(h.drive.position(), 15000.0, 500.0);  // lags by about v * time constants
  h.cw(0x000F);
  h.set(obj::kIpDataRecord, 90000);  // ignored without bit 4
  h.step(200);
  EXPECT_EQ(h.sw() & kBit12, 0);
  EXPECT_NEAR(h.drive.position(), 15000.0, 10.0);
}

TEST(CyclicPosition, FollowsTargetPosition) {
  DriveHarness h;
  h.enable(op_mode::kCyclicPosition);
  EXPECT_NE(h.sw() & kBit12, 0);  // following
  for (int i = 1; i <= 200; ++i) {
    h.set(obj::kTargetPosition, i * 20);
    h.step();
  }
  h.step(100);
  EXPECT_NEAR(h.drive.position(), 4000.0, 5.0);
  EXPECT_EQ(h.sw() & 0x2000, 0);
}

TEST(CyclicPosition, JumpBeyondWindowIsAFollowingError) {
  DriveHarness h;
  h.enable(op_mode::kCyclicPosition);
  h.set(obj::kFollowingErrorWindow, 1000);
  h.set(obj::kTargetPosition, 400000);
  h.step();
  EXPECT_NE(h.sw() & 0x2000, 0);
  h.run_until([&] { return h.state() == DriveState::Fault; }, 100);
  EXPECT_EQ(h.get(obj::kErrorCode), 0x8611);
}

TEST(CyclicVelocity, FollowsTargetVelocityAndOffset) {
  DriveHarness h;
  h.enable(op_mode::kCyclicVelocity);
  h.set(obj::kTargetVelocity, 40000);
  h.set(obj::kVelocityOffset, 2000);
  h.step(30);
  EXPECT_NEAR(h.drive.velocity(), 42000.0, 10.0);
  EXPECT_NE(h.sw() & kBit12, 0);
}

TEST(CyclicTorque, AppliesTargetPlusOffsetAtOnce) {
  DriveHarness h;
  h.enable(op_mode::kCyclicTorque);
  h.set(obj::kTargetTorque, 80);
  h.set(obj::kTorqueOffset, 20);
  h.step();
  EXPECT_EQ(h.get(obj::kTorqueActual), 100);
  EXPECT_NE(h.sw() & kBit12, 0);
  EXPECT_GT(h.drive.velocity(), 0.0);
}

TEST(LimitSwitches, StopMotionTowardsTheSwitchOnly) {
  DriveModelConfig cfg;
  cfg.positive_limit_position = 20000;
  cfg.negative_limit_position = -20000;
  DriveHarness h(cfg);
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kTargetVelocity, 50000);
  h.step(1000);
  EXPECT_NEAR(h.drive.position(), 20000.0, 100.0);
  EXPECT_EQ(h.drive.velocity(), 0.0);
  EXPECT_NE(h.sw() & kLimit, 0);
  EXPECT_EQ(h.get(obj::kDigitalInputs), din::kPositiveLimit);
  h.set(obj::kTargetVelocity, -50000);  // away from the switch is allowed
  h.step(200);
  EXPECT_LT(h.drive.position(), 15000.0);
  EXPECT_EQ(h.sw() & kLimit, 0);
  EXPECT_EQ(h.get(obj::kDigitalInputs), 0);
  h.step(1000);
  EXPECT_NEAR(h.drive.position(), -20000.0, 100.0);
  EXPECT_EQ(h.get(obj::kDigitalInputs), din::kNegativeLimit);
}

TEST(LimitSwitches, HomeSwitchInput) {
  DriveModelConfig cfg;
  cfg.home_switch_position = 5000;
  DriveHarness h(cfg);
  h.enable(op_mode::kProfileVelocity);
  h.step();
  EXPECT_EQ(h.get(obj::kDigitalInputs), 0);
  h.set(obj::kTargetVelocity, 50000);
  h.step(300);
  EXPECT_EQ(h.get(obj::kDigitalInputs), din::kHomeSwitch);
}

}  // namespace
}  // namespace drivegate::cia402::sim::test
