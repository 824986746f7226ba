#pragma once
// The `profinet` bus type's registration: config/profinet's schema, readers, checks and printout,
// with the wire rules of this adapter (NameOfStation, the C_SDU layout of an AR), and the factory
// of the runtime bus (profinet_bus.hpp). daemon/bus_types.cpp adds it to the build's registry.
#include "config/bus_types.hpp"

namespace drivegate::profinet {

config::BusTypeInfo bus_type();

}  // namespace drivegate::profinet
