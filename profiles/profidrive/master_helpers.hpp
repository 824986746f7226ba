#pragma once
// Small helpers the PROFIdrive master files share.
#include <chrono>

#include "core/axis_types.hpp"
#include "core/clock.hpp"

namespace drivegate::profidrive {

constexpr bool in_fault(core::AxisState s) noexcept {
  return s == core::AxisState::Fault || s == core::AxisState::FaultReactionActive;
}

inline long long ms(core::Duration d) noexcept {
  return static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(d).count());
}

}  // namespace drivegate::profidrive
