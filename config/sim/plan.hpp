#pragma once
// The plan parts of the `sim` bus type, held in the plan's Sections: its typed bus options
// (BusPlan::section<SimBusOptions>()) and an axis' `sim:` section (SimAxisOptions).
#include <optional>

#include "config/plan.hpp"

namespace drivegate::config {

// Settings of the built-in simulated drive for one axis (the `sim:` section), already converted
// from user units to the drive's units so the drive model never sees user units.
struct SimAxisOptions {
  double start_position = 0;  // drive position units
  std::optional<double> home_switch_position;            // drive position units; none = no switch
  std::optional<double> negative_limit_switch_position;  // drive position units
  std::optional<double> positive_limit_switch_position;  // drive position units
  double max_velocity = 0;      // drive velocity units: the motor's top speed
  double max_acceleration = 0;  // drive acceleration units
};

// Options of the `sim` bus type.
struct SimBusOptions {
  int acyclic_latency_cycles = 1;  // cycles before an acyclic request is answered
};

}  // namespace drivegate::config
