#include "profiles/profidrive/scaling.hpp"

#include <cmath>

namespace drivegate::profidrive {

std::optional<std::int16_t> nsoll_from_rpm(double rpm) noexcept {
  return core::to_int16(rpm * kNsollFullScale / kAkdMaxSpeedRpm);
}

std::int16_t nsoll_from_rpm_saturating(double rpm) noexcept {
  if (std::isnan(rpm)) return 0;
  const double r = std::round(rpm * kNsollFullScale / kAkdMaxSpeedRpm);
  if (r >= 32767.0) return 32767;
  if (r <= -32768.0) return -32768;
  return static_cast<std::int16_t>(r);
}

double rpm_from_speed_word(std::int16_t raw) noexcept { return raw * kAkdMaxSpeedRpm / kNsollFullScale; }

std::optional<std::uint32_t> mdi_velocity_from_rpm(double rpm) noexcept {
  if (!(rpm >= 0)) return std::nullopt;  // also NaN
  return core::to_uint32(rpm * kMdiVelocityFullScale / kAkdMaxSpeedRpm);
}

double rpm_from_mdi_velocity(std::uint32_t raw) noexcept { return raw * kAkdMaxSpeedRpm / kMdiVelocityFullScale; }

std::optional<std::uint16_t> mdi_acc_from_rpm_per_s(double rpm_per_s, double full_scale_rpm_per_s) noexcept {
  if (!(rpm_per_s > 0) || !(full_scale_rpm_per_s > 0)) return std::nullopt;
  const auto raw = core::to_uint32(rpm_per_s * kMdiAccFullScale / full_scale_rpm_per_s);
  if (!raw || *raw == 0 || *raw > 0xFFFFU) return std::nullopt;
  return static_cast<std::uint16_t>(*raw);
}

double rpm_per_s_from_mdi_acc(std::uint16_t raw, double full_scale_rpm_per_s) noexcept {
  return raw * full_scale_rpm_per_s / kMdiAccFullScale;
}

std::optional<double> acc_full_scale_from_pnu1008(std::uint16_t pnu1008) noexcept {
  if (pnu1008 == 0) return std::nullopt;
  return pnu1008 * kMdiAccDefaultRpmPerS / kMdiAccFullScale;
}

std::optional<double> counts_per_rev(unsigned single_turn_bits) noexcept {
  if (single_turn_bits == 0 || single_turn_bits > 31) return std::nullopt;
  return std::ldexp(1.0, static_cast<int>(single_turn_bits));
}

double amps_from_current_word(std::int16_t raw, double peak_current_a) noexcept {
  return raw * peak_current_a / kCurrentFullScale;
}

std::optional<core::NativeUnits> native_units(const AkdScaling& s) noexcept {
  const auto per_rev = counts_per_rev(s.single_turn_bits);
  if (!per_rev || !(s.acc_full_scale_rpm_per_s > 0) || !std::isfinite(s.acc_full_scale_rpm_per_s)) return std::nullopt;
  core::NativeUnits n;
  n.position_per_rev = *per_rev;
  n.velocity_per_rps = kNativeVelocityPerRps;
  n.acceleration_per_rps2 = kMdiAccFullScale * 60.0 / s.acc_full_scale_rpm_per_s;
  if (s.peak_current_a > 0 && s.rated_current_a > 0) n.torque_per_rated = kCurrentFullScale * s.rated_current_a / s.peak_current_a;
  return n;
}

std::optional<std::int16_t> nsoll_from_native(std::int32_t velocity) noexcept {
  return core::to_int16(velocity / 65536.0);
}

std::int32_t native_from_nist(std::int16_t raw) noexcept { return static_cast<std::int32_t>(raw) * 65536; }

std::optional<std::uint32_t> mdi_velocity_from_native(std::uint32_t velocity) noexcept {
  if (velocity >= 0x80000000U) return std::nullopt;
  return velocity * 2U;
}

std::optional<std::uint16_t> mdi_acc_from_native(std::uint32_t acceleration) noexcept {
  if (acceleration > 0xFFFFU) return std::nullopt;
  return static_cast<std::uint16_t>(acceleration);
}

}  // namespace drivegate::profidrive
