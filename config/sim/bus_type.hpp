#pragma once
// The `sim` bus type's configuration: its option, the axes' `sim:` section (the simulated drive,
// converted to drive units) and its printout row. adapters/sim adds the bus itself.
#include "config/bus_types.hpp"

namespace drivegate::config {

BusTypeInfo sim_bus_type();

}  // namespace drivegate::config
