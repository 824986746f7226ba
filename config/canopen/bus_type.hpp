#pragma once
// The `canopen` bus type's configuration: schema, the readers and checks of its options and of
// the axes' and device profiles' `canopen:` sections, its printout rows and the resource a bus
// holds. adapters/canopen adds what needs the adapter: the bus load check, the bus itself.
#include "config/bus_types.hpp"

namespace drivegate::config {

BusTypeInfo canopen_bus_type();

}  // namespace drivegate::config
