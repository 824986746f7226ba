#pragma once
// The `ethercat` bus type's configuration: its options and `io:` list, the axis section, the
// device profiles' `ethercat:` section and the checks across a bus. The adapter
// (adapters/ethercat) adds the factory, the scan and the checks that need its process image.
#include "config/bus_types.hpp"

namespace drivegate::config {

BusTypeInfo ethercat_bus_type();

}  // namespace drivegate::config
