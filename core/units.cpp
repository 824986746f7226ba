#include "core/units.hpp"

#include <cmath>
#include <limits>

namespace drivegate::core {

UnitConverter::UnitConverter(const Mechanics& m, const NativeUnits& n) noexcept {
  // motor revolutions per user unit
  const double rev_per_user = m.gear_ratio / m.feed;
  pos_ = rev_per_user * n.position_per_rev;
  vel_ = rev_per_user * n.velocity_per_rps;
  acc_ = rev_per_user * n.acceleration_per_rps2;
  torque_in_nm_ = m.rated_torque > 0;
  tq_ = m.rated_torque > 0 ? n.torque_per_rated / m.rated_torque : n.torque_per_rated / 100.0;
}

namespace {
template <typename T>
std::optional<T> checked_round(double v) noexcept {
  if (!std::isfinite(v)) return std::nullopt;
  const double r = std::round(v);
  if (r < static_cast<double>(std::numeric_limits<T>::min()) ||
      r > static_cast<double>(std::numeric_limits<T>::max()))
    return std::nullopt;
  return static_cast<T>(r);
}
}  // namespace

std::optional<std::int32_t> to_int32(double v) noexcept { return checked_round<std::int32_t>(v); }
std::optional<std::uint32_t> to_uint32(double v) noexcept { return checked_round<std::uint32_t>(v); }
std::optional<std::int16_t> to_int16(double v) noexcept { return checked_round<std::int16_t>(v); }

}  // namespace drivegate::core
