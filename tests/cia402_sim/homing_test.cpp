// Homing mode on the drive side [AKD digest §9; nord §5.5, §6].
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "tests/cia402_sim/drive_harness.hpp"

namespace drivegate::cia402::sim::test {
namespace {

constexpr std::uint16_t kReached = 0x0400;
constexpr std::uint16_t kAttained = 0x1000;
constexpr std::uint16_t kError = 0x2000;
constexpr std::int32_t kHomeOffset = 500;

DriveModelConfig machine() {
  DriveModelConfig cfg;
  cfg.negative_limit_position = -30000;
  cfg.positive_limit_position = 30000;
  cfg.index_pulse_offset = 1234;  // index pulses at 1234 + k * 10000 (physical)
  return cfg;
}

class Homing : public ::testing::Test {
 protected:
  void home(std::int8_t method) {
    h.set(obj::kHomingMethod, method);
    h.set(obj::kHomeOffset, kHomeOffset);
    h.enable(op_mode::kHoming);
    h.cw(0x001F);
    h.step();
  }
  bool finished() const { return (h.sw() & (kAttained | kError)) != 0 && (h.sw() & kReached) != 0; }
  // Creeps in pp towards `beyond` until a limit switch stops the motor; returns where it stopped
  // and which switch did it.
  std::pair<double, std::int64_t> switch_towards(std::int32_t beyond) {
    h.set(obj::kModesOfOperation, op_mode::kProfilePosition);
    h.cw(0x000F);
    h.step();
    h.set(obj::kProfileVelocity, 5000);
    h.set(obj::kTargetPosition, beyond);
    h.cw(0x001F);
    h.step();
    h.cw(0x000F);
    h.step(5);
    EXPECT_GE(h.run_until([&] { return (h.sw() & 0x0800) != 0 && std::abs(h.drive.velocity()) < 1.0; }, 60000), 0);
    return {h.drive.position(), h.get(obj::kDigitalInputs)};
  }
  void expect_switch(std::int32_t beyond, double where, std::uint32_t which) {
    const auto [pos, inputs] = switch_towards(beyond);
    EXPECT_NEAR(pos, where, 15.0);
    EXPECT_EQ(inputs, which);
  }
  void expect_attained() {
    ASSERT_GE(h.run_until([&] { return finished(); }, 30000), 0);
    EXPECT_EQ(h.sw() & (kAttained | kError | kReached), kAttained | kReached);
    EXPECT_NEAR(h.drive.position(), kHomeOffset, 10.0);
  }
  DriveHarness h{machine()};
};

TEST_F(Homing, Method17NegativeLimitSwitchEdge) {
  home(17);
  EXPECT_EQ(h.sw() & (kAttained | kError | kReached), 0);  // homing in progress
  expect_attained();
  // Home is the switch edge: the switch is active just below the home position.
  expect_switch(-100000, kHomeOffset, din::kNegativeLimit);
}

TEST_F(Homing, Method18PositiveLimitSwitchEdge) {
  home(18);
  expect_attained();
  expect_switch(100000, kHomeOffset, din::kPositiveLimit);
}

TEST_F(Homing, Method1NegativeLimitThenIndex) {
  home(1);
  expect_attained();
  // The first index pulse above the switch is at 1234 - 30000: the switch lies 1234 below home.
  expect_switch(-100000, kHomeOffset - 1234, din::kNegativeLimit);
}

TEST_F(Homing, Method2PositiveLimitThenIndex) {
  home(2);
  expect_attained();
  // The first index pulse below the switch at 30000 is 21234: the switch lies 8766 above home.
  expect_switch(100000, kHomeOffset + 8766, din::kPositiveLimit);
}

TEST_F(Homing, Method33IndexPulseNegative) {
  home(33);
  expect_attained();
  // From 0 downwards the next pulse is -8766; the negative switch is 21234 below it.
  expect_switch(-100000, kHomeOffset - 21234, din::kNegativeLimit);
}

TEST_F(Homing, Method34IndexPulsePositive) {
  home(34);
  expect_attained();
  // From 0 upwards the next pulse is 1234; the positive switch is 28766 above it.
  expect_switch(100000, kHomeOffset + 28766, din::kPositiveLimit);
}

TEST_F(Homing, Method35SetsTheCurrentPosition) {
  home(35);
  h.step();
  EXPECT_EQ(h.sw() & (kAttained | kError | kReached), kAttained | kReached);
  EXPECT_EQ(h.get(obj::kPositionActual), kHomeOffset);
}

TEST_F(Homing, Method37SetsTheCurrentPosition) {
  home(37);
  h.step();
  EXPECT_EQ(h.sw() & (kAttained | kError | kReached), kAttained | kReached);
  EXPECT_EQ(h.get(obj::kPositionActual), kHomeOffset);
}

TEST_F(Homing, UnsupportedMethodIsAHomingError) {
  home(8);  // home switch method, not in the default list
  h.step();
  EXPECT_EQ(h.sw() & (kAttained | kError | kReached), kError | kReached);
}

TEST_F(Homing, MissingSwitchIsAHomingError) {
  h.drive.set_limit_switch_positions(std::nullopt, 30000);
  home(17);
  h.step();
  EXPECT_EQ(h.sw() & (kAttained | kError), kError);
}

TEST_F(Homing, WrongLimitSwitchDuringIndexSearchIsAHomingError) {
  h.drive.set_limit_switch_positions(-30000, 800);  // positive switch before the first pulse at 1234
  home(34);
  ASSERT_GE(h.run_until([&] { return finished(); }), 0);
  EXPECT_EQ(h.sw() & (kAttained | kError), kError);
}

TEST_F(Homing, ClearingBit4InterruptsHoming) {
  home(17);
  h.step(300);
  ASSERT_LT(h.drive.velocity(), -10000.0);
  h.cw(0x000F);
  h.step();
  EXPECT_EQ(h.sw() & (kAttained | kError), 0);
  ASSERT_GE(h.run_until([&] { return (h.sw() & kReached) != 0; }), 0);  // interrupted, at standstill
  EXPECT_LT(std::abs(h.drive.velocity()), 100.0);
  EXPECT_EQ(h.sw() & (kAttained | kError), 0);
  h.cw(0x001F);  // a new rising edge starts again
  h.step();
  expect_attained();
}

TEST_F(Homing, MethodCannotChangeWhileHoming) {
  home(17);
  h.step(10);
  EXPECT_EQ(h.drive.write_object(obj::kHomingMethod.id, 18), 0x08000022U);
  EXPECT_EQ(h.drive.write_object(obj::kHomingSpeedSwitch.id, 600000), 0x06090031U);  // above max motor speed
}

}  // namespace
}  // namespace drivegate::cia402::sim::test
