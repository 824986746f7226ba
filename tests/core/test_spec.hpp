#pragma once
#include "core/axis_spec.hpp"

namespace drivegate::test {

// A linear axis in mm: 10 mm per motor rev, 10000 counts per rev (1000 counts per mm).
inline core::AxisSpec linear_axis_spec() {
  core::AxisSpec s;
  s.name = "x";
  s.device = "generic-cia402";
  s.user_unit = "mm";
  for (auto m : {core::Mode::ProfilePosition, core::Mode::ProfileVelocity, core::Mode::ProfileTorque,
                 core::Mode::Homing, core::Mode::CyclicPosition})
    s.modes.add(m);
  s.homing_methods = {1, 2, 17, 18, 33, 34, 35, 37};
  s.units = core::UnitConverter(core::Mechanics{10.0, 1.0, 0}, core::NativeUnits{10000, 10000, 10000, 1000});
  s.limits.min_position = -100;
  s.limits.max_position = 500;
  s.limits.max_velocity = 200;
  s.limits.max_acceleration = 2000;
  s.limits.max_torque = 150;
  s.defaults.velocity = 50;
  s.defaults.acceleration = 500;
  s.defaults.deceleration = 400;
  s.command_timeout = std::chrono::milliseconds(100);
  return s;
}

}  // namespace drivegate::test
