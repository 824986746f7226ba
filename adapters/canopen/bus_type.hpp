#pragma once
// The `canopen` bus type's registration: config/canopen's schema, readers, checks and printout
// rows, plus what needs this adapter: the bus load check and row (plan_load.hpp) and the factory.
// daemon/bus_types.cpp adds it to the build's registry.
#include "config/bus_types.hpp"

namespace drivegate::canopen {

config::BusTypeInfo bus_type();

}  // namespace drivegate::canopen
