#include "core/units.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace drivegate::core;

TEST(Units, BallScrewWithGearboxInEncoderCounts) {
  // 5 mm per load rev, 3 motor revs per load rev, 131072 counts per motor rev, velocity in counts/s.
  Mechanics m{5.0, 3.0, 0};
  NativeUnits n{131072, 131072, 131072, 1000};
  UnitConverter u(m, n);
  EXPECT_DOUBLE_EQ(u.position_to_drive(5.0), 3 * 131072.0);
  EXPECT_DOUBLE_EQ(u.velocity_to_drive(10.0), 2 * 3 * 131072.0);
  EXPECT_DOUBLE_EQ(u.position_to_user(3 * 131072.0), 5.0);
  EXPECT_DOUBLE_EQ(u.torque_to_drive(50.0), 500.0);  // 50 % of rated = 500 per mille
}

TEST(Units, AkdVelocityInThousandthRpm) {
  // A rotary axis in degrees, direct drive; AKD pv velocity unit 1/1000 rpm (60000 per rev/s).
  Mechanics m{360.0, 1.0, 0};
  NativeUnits n{1048576, 60000, 60000, 1000};
  UnitConverter u(m, n);
  EXPECT_DOUBLE_EQ(u.velocity_to_drive(360.0), 60000.0);  // 1 rev/s = 60 rpm = 60000 mrpm
  EXPECT_NEAR(u.velocity_to_user(1000.0), 6.0, 1e-12);    // 1 rpm = 6 deg/s
}

TEST(Units, TorqueInNewtonMetresWhenRatedTorqueIsGiven) {
  UnitConverter u(Mechanics{1, 1, 2.5}, NativeUnits{});
  EXPECT_DOUBLE_EQ(u.torque_to_drive(2.5), 1000.0);
  EXPECT_DOUBLE_EQ(u.torque_to_user(500.0), 1.25);
}

TEST(Units, RoundedConversionsRefuseWhatDoesNotFit) {
  EXPECT_EQ(to_int32(1.6), 2);
  EXPECT_EQ(to_int32(-1.6), -2);
  EXPECT_FALSE(to_int32(3e9).has_value());
  EXPECT_FALSE(to_uint32(-1.0).has_value());
  EXPECT_FALSE(to_int16(40000.0).has_value());
  EXPECT_FALSE(to_int32(std::numeric_limits<double>::quiet_NaN()).has_value());
  EXPECT_FALSE(to_int32(std::numeric_limits<double>::infinity()).has_value());
}
