#include "profiles/cia402/op_modes.hpp"

#include "profiles/cia402/objects.hpp"

namespace drivegate::cia402 {

std::optional<std::int8_t> to_op_mode(core::Mode mode) noexcept {
  using core::Mode;
  switch (mode) {
    case Mode::ProfilePosition: return op_mode::kProfilePosition;
    case Mode::Velocity: return op_mode::kVelocity;
    case Mode::ProfileVelocity: return op_mode::kProfileVelocity;
    case Mode::ProfileTorque: return op_mode::kProfileTorque;
    case Mode::Homing: return op_mode::kHoming;
    case Mode::InterpolatedPosition: return op_mode::kInterpolatedPosition;
    case Mode::CyclicPosition: return op_mode::kCyclicPosition;
    case Mode::CyclicVelocity: return op_mode::kCyclicVelocity;
    case Mode::CyclicTorque: return op_mode::kCyclicTorque;
    case Mode::None:
    case Mode::TraversingBlock: return std::nullopt;
  }
  return std::nullopt;
}

core::Mode from_op_mode(std::int8_t value) noexcept {
  using core::Mode;
  switch (value) {
    case op_mode::kProfilePosition: return Mode::ProfilePosition;
    case op_mode::kVelocity: return Mode::Velocity;
    case op_mode::kProfileVelocity: return Mode::ProfileVelocity;
    case op_mode::kProfileTorque: return Mode::ProfileTorque;
    case op_mode::kHoming: return Mode::Homing;
    case op_mode::kInterpolatedPosition: return Mode::InterpolatedPosition;
    case op_mode::kCyclicPosition: return Mode::CyclicPosition;
    case op_mode::kCyclicVelocity: return Mode::CyclicVelocity;
    case op_mode::kCyclicTorque: return Mode::CyclicTorque;
    default: return Mode::None;
  }
}

}  // namespace drivegate::cia402
