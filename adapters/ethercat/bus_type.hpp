#pragma once
// The `ethercat` bus type's registration: config/ethercat's schema, readers and checks, plus what
// needs this adapter: the process image check (the frame must fit the cycle), its printout rows
// and the factory. daemon/bus_types.cpp adds it to the build's registry.
#include "config/bus_types.hpp"

namespace drivegate::ethercat {

config::BusTypeInfo bus_type();

}  // namespace drivegate::ethercat
