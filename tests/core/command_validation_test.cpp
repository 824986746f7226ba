#include "core/command_validation.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "tests/core/test_spec.hpp"

using namespace drivegate::core;

namespace {
Command move_to(double pos) {
  Command c;
  c.id = 7;
  c.kind = CommandKind::Move;
  c.position = pos;
  return c;
}
}  // namespace

TEST(CommandValidation, MoveIsConvertedWithDefaults) {
  const auto spec = drivegate::test::linear_axis_spec();
  const auto r = validate_and_convert(spec, move_to(12.5), 0);
  ASSERT_TRUE(r.ok) << r.reason.view();
  EXPECT_EQ(r.drive.mode, Mode::ProfilePosition);
  EXPECT_EQ(r.drive.target_position, 12500);
  EXPECT_EQ(r.drive.profile_velocity, 50000u);       // 50 mm/s default
  EXPECT_EQ(r.drive.profile_acceleration, 500000u);  // 500 mm/s^2 default
  EXPECT_EQ(r.drive.profile_deceleration, 400000u);
}

TEST(CommandValidation, NanAndInfinityAreRejected) {
  const auto spec = drivegate::test::linear_axis_spec();
  auto r = validate_and_convert(spec, move_to(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("NaN"), std::string_view::npos) << r.reason.view();
  Command v;
  v.kind = CommandKind::Velocity;
  v.velocity = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(validate_and_convert(spec, v, 0).ok);
}

TEST(CommandValidation, PositionOutsideLimitsSaysWhichLimits) {
  const auto spec = drivegate::test::linear_axis_spec();
  const auto r = validate_and_convert(spec, move_to(600), 0);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("[-100, 500] mm"), std::string_view::npos) << r.reason.view();
  // A relative move is checked at its end point and becomes an absolute target.
  auto rel = move_to(50);
  rel.relative = true;
  EXPECT_FALSE(validate_and_convert(spec, rel, 480).ok);
  const auto ok = validate_and_convert(spec, rel, 400);
  ASSERT_TRUE(ok.ok);
  EXPECT_EQ(ok.drive.target_position, 450000);
  EXPECT_FALSE(ok.drive.relative);
}

TEST(CommandValidation, RatesAboveLimitsAreRejectedNotClamped) {
  const auto spec = drivegate::test::linear_axis_spec();
  auto c = move_to(10);
  c.velocity = 250;
  EXPECT_FALSE(validate_and_convert(spec, c, 0).ok);
  Command v;
  v.kind = CommandKind::Velocity;
  v.velocity = -201;
  EXPECT_FALSE(validate_and_convert(spec, v, 0).ok);
  v.velocity = -200;
  const auto r = validate_and_convert(spec, v, 0);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.drive.target_velocity, -200000);
  EXPECT_EQ(r.drive.mode, Mode::ProfileVelocity);
}

TEST(CommandValidation, UnsupportedModeListsTheSupportedOnes) {
  const auto spec = drivegate::test::linear_axis_spec();
  Command c;
  c.kind = CommandKind::SetMode;
  c.mode = Mode::CyclicTorque;
  const auto r = validate_and_convert(spec, c, 0);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("does not support mode cyclic_torque"), std::string_view::npos) << r.reason.view();
  EXPECT_NE(r.reason.view().find("pp, pv, tq, hm, csp"), std::string_view::npos) << r.reason.view();
}

TEST(CommandValidation, VelocityFallsBackToVlWhenTheDeviceHasNoPv) {
  auto spec = drivegate::test::linear_axis_spec();
  spec.modes = ModeSet{};
  spec.modes.add(Mode::Velocity);
  Command v;
  v.kind = CommandKind::Velocity;
  v.velocity = 10;
  const auto r = validate_and_convert(spec, v, 0);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.drive.mode, Mode::Velocity);
}

TEST(CommandValidation, VelocityRunsInTheRequestedOfPvAndVl) {
  auto spec = drivegate::test::linear_axis_spec();
  spec.modes.add(Mode::ProfileVelocity);
  spec.modes.add(Mode::Velocity);
  Command v;
  v.kind = CommandKind::Velocity;
  v.velocity = 10;
  EXPECT_EQ(validate_and_convert(spec, v, 0).drive.mode, Mode::ProfileVelocity);
  v.mode = Mode::Velocity;
  EXPECT_EQ(validate_and_convert(spec, v, 0).drive.mode, Mode::Velocity);
  v.mode = Mode::Homing;  // not a velocity mode: ignored
  EXPECT_EQ(validate_and_convert(spec, v, 0).drive.mode, Mode::ProfileVelocity);
}

TEST(CommandValidation, HomingMethodMustBeSupported) {
  const auto spec = drivegate::test::linear_axis_spec();
  Command h;
  h.kind = CommandKind::Home;
  h.homing_method = 19;
  EXPECT_FALSE(validate_and_convert(spec, h, 0).ok);
  h.homing_method = 0;  // configured default (35)
  const auto r = validate_and_convert(spec, h, 0);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.drive.homing_method, 35);
}

TEST(CommandValidation, TorqueOutsideLimitAndOverflowAreRejected) {
  auto spec = drivegate::test::linear_axis_spec();
  Command t;
  t.kind = CommandKind::Torque;
  t.torque = 151;
  EXPECT_FALSE(validate_and_convert(spec, t, 0).ok);
  spec.limits.max_torque = 0;  // no limit configured: the int16 range still applies
  t.torque = 5000;             // 50000 per mille does not fit INT16
  EXPECT_FALSE(validate_and_convert(spec, t, 0).ok);
}

// Validated in drive units after conversion: a value that becomes 0 would make the drive keep its
// previous profile velocity (a move at 1e-300 mm/s ran at 200 mm/s), so it is refused.
TEST(CommandValidation, RatesThatRoundToZeroDriveUnitsAreRefused) {
  const auto spec = drivegate::test::linear_axis_spec();  // 1000 drive units per mm (and per mm/s)
  auto c = move_to(10);
  c.velocity = 1e-300;
  auto r = validate_and_convert(spec, c, 0);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("move velocity 1e-300 mm/s is 0 in drive units"), std::string_view::npos)
      << r.reason.view();
  EXPECT_NE(r.reason.view().find("resolution is 0.001 mm/s"), std::string_view::npos) << r.reason.view();
  c.velocity = 0.0004;  // 0.4 drive units: rounds to 0
  EXPECT_FALSE(validate_and_convert(spec, c, 0).ok);
  c.velocity = 0.0006;  // 0.6: rounds to 1, the slowest the drive can go
  r = validate_and_convert(spec, c, 0);
  ASSERT_TRUE(r.ok) << r.reason.view();
  EXPECT_EQ(r.drive.profile_velocity, 1u);
  c.velocity = 10;
  c.acceleration = 1e-9;
  r = validate_and_convert(spec, c, 0);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("acceleration"), std::string_view::npos) << r.reason.view();
  c.acceleration = 0;
  c.deceleration = 1e-9;
  EXPECT_FALSE(validate_and_convert(spec, c, 0).ok);

  // A velocity command of exactly 0 is a legitimate "stand still"; a tiny one of either sign is not.
  Command v;
  v.kind = CommandKind::Velocity;
  v.velocity = 0;
  EXPECT_TRUE(validate_and_convert(spec, v, 0).ok);
  v.velocity = -1e-12;
  r = validate_and_convert(spec, v, 0);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("velocity -1e-12 mm/s is 0 in drive units"), std::string_view::npos)
      << r.reason.view();

  Command t;
  t.kind = CommandKind::Torque;
  t.torque = 0.01;  // 0.1 per mille
  r = validate_and_convert(spec, t, 0);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("torque 0.01 % is 0 in drive units"), std::string_view::npos) << r.reason.view();

  Command h;
  h.kind = CommandKind::Home;
  h.homing_search_velocity = 1e-7;
  EXPECT_FALSE(validate_and_convert(spec, h, 0).ok);
}

// Positions are quantised to the drive's resolution as usual; only overflow is refused.
TEST(CommandValidation, PositionsRoundButMustFitTheDriveObject) {
  auto spec = drivegate::test::linear_axis_spec();
  auto r = validate_and_convert(spec, move_to(1e-7), 0);
  ASSERT_TRUE(r.ok) << r.reason.view();
  EXPECT_EQ(r.drive.target_position, 0);
  spec.limits = AxisLimits{};  // no soft limits: the 32-bit object is the only bound
  r = validate_and_convert(spec, move_to(3e6), 0);  // 3e9 counts
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.reason.view().find("move target 3e+06 mm does not fit the drive's 32-bit object"), std::string_view::npos)
      << r.reason.view();
}

TEST(CommandValidation, SetpointsAreCheckedForTheModeTheyFeed) {
  const auto spec = drivegate::test::linear_axis_spec();
  Text why;
  Setpoint sp;
  sp.position = 20;
  auto d = convert_setpoint(spec, Mode::CyclicPosition, sp, why);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->position, 20000);
  sp.position = 900;
  EXPECT_FALSE(convert_setpoint(spec, Mode::CyclicPosition, sp, why).has_value());
  EXPECT_FALSE(convert_setpoint(spec, Mode::ProfilePosition, sp, why).has_value());
  EXPECT_NE(why.view().find("takes no streamed set-points"), std::string_view::npos);
}
