#pragma once
// Checks of a command against the axis' configuration before it reaches the drive: finite
// numbers, configured limits, modes the device supports, homing methods. Each rejection says what
// was wrong and what is allowed, in words a person can act on. State-dependent checks ("axis in
// fault") belong to the profile controller, which knows the drive's present state.
#include <optional>

#include "core/axis_spec.hpp"
#include "core/command.hpp"

namespace drivegate::core {

struct Conversion {
  bool ok = false;
  DriveCommand drive;
  Text reason;  // when !ok
};

// The mode a command runs in on this axis (e.g. a velocity command uses pv, or vl where the device
// has no pv). Mode::None for kinds that do not select a mode (enable, stop, ...).
Mode mode_for(CommandKind kind, const ModeSet& modes, Mode requested) noexcept;

// Validates `cmd` for the axis and converts it to drive units. `actual_position` (user units) is
// used to check the end point of relative moves against the position limits.
Conversion validate_and_convert(const AxisSpec& spec, const Command& cmd, double actual_position) noexcept;

// Validates and converts a streaming set-point for the given cyclic mode.
std::optional<DriveSetpoint> convert_setpoint(const AxisSpec& spec, Mode mode, const Setpoint& sp,
                                              Text& reason) noexcept;

}  // namespace drivegate::core
