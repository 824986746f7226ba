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

// Validates `cmd` for the axis and converts it to drive units. A relative move becomes an
// absolute target here, `relative_base + distance` (user units), and that end point is what the
// limits are checked against: the drive's own base for relative moves differs between drives
// (last target or actual position), which would make a limit check on the distance meaningless.
// The runner passes the target of a move still in flight, else the actual position.
Conversion validate_and_convert(const AxisSpec& spec, const Command& cmd, double relative_base) noexcept;

// Validates and converts a streaming set-point for the given cyclic mode.
std::optional<DriveSetpoint> convert_setpoint(const AxisSpec& spec, Mode mode, const Setpoint& sp,
                                              Text& reason) noexcept;

}  // namespace drivegate::core
