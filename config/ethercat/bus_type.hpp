#pragma once
// The `ethercat` bus type's configuration. So far the device profiles' `ethercat:` section: a
// configuration may name the type, and profiles carry their EtherCAT data, but no adapter is linked
// in yet (no make_bus: a bus of this type is refused with that reason).
#include "config/bus_types.hpp"

namespace drivegate::config {

BusTypeInfo ethercat_bus_type();

}  // namespace drivegate::config
