#pragma once
// Small helpers the CiA 402 master files share: the fault-state test and the texts that go into
// replies (mode names, durations in ms).
#include <chrono>
#include <string_view>

#include "core/axis_types.hpp"
#include "core/clock.hpp"

namespace drivegate::cia402 {

// Fault reaction active counts as fault: the drive is already on its way there and ignores motion.
constexpr bool in_fault(core::AxisState s) noexcept {
  return s == core::AxisState::Fault || s == core::AxisState::FaultReactionActive;
}

inline std::string_view mode_name(core::Mode m) noexcept {
  return m == core::Mode::None ? std::string_view("none") : core::mode_short_name(m);
}

inline long long ms(core::Duration d) noexcept {
  return static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(d).count());
}

}  // namespace drivegate::cia402
