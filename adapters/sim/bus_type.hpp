#pragma once
// The `sim` bus type's registration: config/sim's schema, reader and printout row, and the
// factory of SimBus. daemon/bus_types.cpp adds it to the build's registry.
#include "config/bus_types.hpp"

namespace drivegate::sim {

config::BusTypeInfo bus_type();

}  // namespace drivegate::sim
