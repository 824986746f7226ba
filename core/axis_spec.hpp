#pragma once
// Everything the cycle thread needs to know about one axis, compiled from the configuration and
// the device profile before any thread starts.
#include <cstdint>
#include <string>
#include <vector>

#include "core/axis_types.hpp"
#include "core/clock.hpp"
#include "core/units.hpp"

namespace drivegate::core {

struct AxisLimits {
  // Soft position limits in user units; min > max means "no limit".
  double min_position = 1.0;
  double max_position = -1.0;
  double max_velocity = 0;      // user units/s; 0 = no limit
  double max_acceleration = 0;  // user units/s^2; 0 = no limit
  double max_torque = 0;        // percent or Nm; 0 = no limit
  [[nodiscard]] bool has_position_limits() const noexcept { return min_position <= max_position; }
};

struct AxisDefaults {
  double velocity = 0;      // profile velocity for moves that give none
  double acceleration = 0;  // for moves and jogs that give none
  double deceleration = 0;
  double torque_slope = 0;  // percent (or Nm) per second; 0 = drive default
};

struct HomingSettings {
  std::int16_t method = 35;  // CiA 402 homing method (35/37: current position)
  double offset = 0;         // user units
  double search_velocity = 0;
  double zero_velocity = 0;
  double acceleration = 0;
  Duration timeout = std::chrono::seconds(60);
};

// What the axis does when its command source goes silent (DESIGN.md §4 safety rules).
enum class TimeoutStop : std::uint8_t { QuickStop, Halt };

struct AxisSpec {
  std::string name;
  std::string device;  // device profile name
  ModeSet modes;       // modes the device supports (and the axis allows)
  std::vector<std::int16_t> homing_methods;  // methods the device supports; empty = any
  Mode default_mode = Mode::None;
  UnitConverter units;
  std::string user_unit = "rev";
  AxisLimits limits;
  AxisDefaults defaults;
  HomingSettings homing;
  Duration command_timeout = std::chrono::milliseconds(500);
  TimeoutStop timeout_stop = TimeoutStop::QuickStop;
  Duration enable_step_timeout = std::chrono::seconds(2);  // per state-machine step
};

}  // namespace drivegate::core
