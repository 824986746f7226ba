#pragma once
// The `profinet` bus type's configuration: its options, the `devices:` and `io:` lists, the axis
// section, the device profiles' `profidrive:` section, the checks across a bus and the printout.
// The adapter (adapters/profinet) hands in the wire rules it owns (NameOfStation, C_SDU layout).
#include "config/bus_types.hpp"
#include "config/profinet/wire_rules.hpp"

namespace drivegate::config {

BusTypeInfo profinet_bus_type(const ProfinetWireRules& rules);

}  // namespace drivegate::config
