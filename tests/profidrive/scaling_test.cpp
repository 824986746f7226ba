// AKD scaling against akd-profinet-profidrive.md §17 (and §15.1/§20.3 for the S7 example values).
#include "profiles/profidrive/scaling.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/units.hpp"

namespace drivegate::profidrive {
namespace {

TEST(ProfidriveScaling, SpeedWord) {
  // §17.1: 60 rpm = 163.84; the manual truncates to 163 (0x00A3), the helper rounds to nearest.
  EXPECT_EQ(nsoll_from_rpm(60.0), std::optional<std::int16_t>(164));
  EXPECT_NEAR(rpm_from_speed_word(0x00A3), 59.70, 0.01);   // §20.3 set-point "about 60 rpm"
  EXPECT_NEAR(rpm_from_speed_word(0x009E), 57.86, 0.01);   // §20.3 actual speed 158
  EXPECT_DOUBLE_EQ(rpm_from_speed_word(0x4000), 6000.0);   // §25.1
  EXPECT_DOUBLE_EQ(rpm_from_speed_word(-32768), -12000.0);
  EXPECT_EQ(nsoll_from_rpm(-12000.0), std::optional<std::int16_t>(-32768));
  EXPECT_EQ(nsoll_from_rpm(11999.6), std::optional<std::int16_t>(32767));
  // +12000 rpm is 2^15: refused, or clamped by the saturating form.
  EXPECT_FALSE(nsoll_from_rpm(12000.0).has_value());
  EXPECT_FALSE(nsoll_from_rpm(-12001.0).has_value());
  EXPECT_FALSE(nsoll_from_rpm(std::numeric_limits<double>::quiet_NaN()).has_value());
  EXPECT_FALSE(nsoll_from_rpm(std::numeric_limits<double>::infinity()).has_value());
  EXPECT_EQ(nsoll_from_rpm_saturating(12000.0), 32767);
  EXPECT_EQ(nsoll_from_rpm_saturating(-1e9), -32768);
  EXPECT_EQ(nsoll_from_rpm_saturating(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(nsoll_from_rpm_saturating(60.0), 164);
}

TEST(ProfidriveScaling, MdiVelocity) {
  // §17.1 [INF]: 60 rpm -> 21 474 836 = 0x0147AE14.
  EXPECT_EQ(mdi_velocity_from_rpm(60.0), std::optional<std::uint32_t>(0x0147AE14));
  EXPECT_NEAR(rpm_from_mdi_velocity(0x0147AE14), 60.0, 1e-5);
  EXPECT_DOUBLE_EQ(rpm_from_mdi_velocity(0x80000000U), 6000.0);
  EXPECT_FALSE(mdi_velocity_from_rpm(12000.0).has_value());  // 2^32 does not fit
  EXPECT_FALSE(mdi_velocity_from_rpm(-1.0).has_value());
  EXPECT_FALSE(mdi_velocity_from_rpm(std::numeric_limits<double>::quiet_NaN()).has_value());
}

TEST(ProfidriveScaling, MdiAccelerationAndPnu1008) {
  // §17.3: 2^16 = 50e6 rpm/s, one step 762.94 rpm/s ("763" in the table).
  EXPECT_NEAR(rpm_per_s_from_mdi_acc(1), 762.94, 0.01);
  EXPECT_NEAR(rpm_per_s_from_mdi_acc(2), 1525.88, 0.01);  // the table's "1536" is a typo [§23.19]
  EXPECT_NEAR(rpm_per_s_from_mdi_acc(0xFFFF), 50e6 - 762.94, 0.01);
  EXPECT_EQ(mdi_acc_from_rpm_per_s(763.0), std::optional<std::uint16_t>(1));
  EXPECT_EQ(mdi_acc_from_rpm_per_s(100000.0), std::optional<std::uint16_t>(131));
  EXPECT_FALSE(mdi_acc_from_rpm_per_s(100.0).has_value());   // rounds to 0: the drive would not move
  EXPECT_FALSE(mdi_acc_from_rpm_per_s(50e6).has_value());    // 2^16 does not fit
  EXPECT_FALSE(mdi_acc_from_rpm_per_s(-763.0).has_value());
  // Reading (b) of PNU 1008: its value times 762.94 rpm/s is 100 %; a smaller full scale gives
  // finer steps.
  EXPECT_NEAR(acc_full_scale_from_pnu1008(1).value(), 762.94, 0.01);
  EXPECT_NEAR(acc_full_scale_from_pnu1008(0xFFFF).value(), 50e6 - 762.94, 0.01);
  EXPECT_FALSE(acc_full_scale_from_pnu1008(0).has_value());
  const double fs = acc_full_scale_from_pnu1008(1311).value();  // about 1e6 rpm/s
  EXPECT_EQ(mdi_acc_from_rpm_per_s(1000.0, fs), std::optional<std::uint16_t>(66));
}

TEST(ProfidriveScaling, PositionAndCurrent) {
  EXPECT_EQ(counts_per_rev(16), std::optional<double>(65536.0));  // §17.2 default
  EXPECT_EQ(counts_per_rev(20), std::optional<double>(1048576.0));
  EXPECT_FALSE(counts_per_rev(0).has_value());
  EXPECT_FALSE(counts_per_rev(32).has_value());
  // §17.4: -182 on a 3 A AKD (DRV.IPEAK 9 A) is -0.1 A.
  EXPECT_NEAR(amps_from_current_word(-182, 9.0), -0.09998, 1e-5);
  EXPECT_DOUBLE_EQ(amps_from_current_word(16384, 9.0), 9.0);
}

TEST(ProfidriveScaling, NativeUnitsFitTheCoreConverter) {
  const core::NativeUnits n = native_units(AkdScaling{}).value();
  EXPECT_DOUBLE_EQ(n.position_per_rev, 65536.0);
  EXPECT_DOUBLE_EQ(n.velocity_per_rps, 10737418.24);
  EXPECT_DOUBLE_EQ(n.acceleration_per_rps2, 0.0786432);
  EXPECT_DOUBLE_EQ(n.torque_per_rated, core::NativeUnits{}.torque_per_rated);  // currents unknown
  AkdScaling with_currents;
  with_currents.peak_current_a = 9.0;
  with_currents.rated_current_a = 3.0;
  EXPECT_NEAR(native_units(with_currents)->torque_per_rated, 16384.0 / 3.0, 1e-9);
  AkdScaling bad;
  bad.single_turn_bits = 0;
  EXPECT_FALSE(native_units(bad).has_value());
  bad = AkdScaling{};
  bad.acc_full_scale_rpm_per_s = 0;
  EXPECT_FALSE(native_units(bad).has_value());

  // User units in rev (feed 1, gear 1): the core converter, then the signal words.
  const core::UnitConverter u(core::Mechanics{1.0, 1.0, 0}, n);
  const std::int32_t v = core::to_int32(u.velocity_to_drive(1.0)).value();  // 1 rev/s = 60 rpm
  EXPECT_EQ(nsoll_from_native(v), std::optional<std::int16_t>(164));           // 163.84, §17.1
  EXPECT_EQ(mdi_velocity_from_native(static_cast<std::uint32_t>(v)), std::optional<std::uint32_t>(21474836));
  EXPECT_NEAR(u.velocity_to_user(native_from_nist(0x009E)), 57.86 / 60.0, 1e-4);  // §20.3
  EXPECT_EQ(core::to_int32(u.position_to_drive(2.5)), std::optional<std::int32_t>(0x00028000));
  // 1000 rpm/s = 16.67 rev/s^2 -> MDI_ACC 1 (763 rpm/s).
  const std::uint32_t a = core::to_uint32(u.acceleration_to_drive(1000.0 / 60.0)).value();
  EXPECT_EQ(mdi_acc_from_native(a), std::optional<std::uint16_t>(1));
  // The whole int32 range maps onto NSOLL_A except the top (2^15 = +12000 rpm).
  EXPECT_EQ(nsoll_from_native(std::numeric_limits<std::int32_t>::min()), std::optional<std::int16_t>(-32768));
  EXPECT_FALSE(nsoll_from_native(std::numeric_limits<std::int32_t>::max()).has_value());
  EXPECT_EQ(nsoll_from_native(0x7FFF0000), std::optional<std::int16_t>(32767));
  EXPECT_EQ(native_from_nist(-32768), std::numeric_limits<std::int32_t>::min());
  EXPECT_FALSE(mdi_velocity_from_native(0x80000000U).has_value());
  EXPECT_FALSE(mdi_acc_from_native(0x10000U).has_value());
}

}  // namespace
}  // namespace drivegate::profidrive
