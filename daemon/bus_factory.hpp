#pragma once
// Builds the Bus implementation for a compiled bus plan, with the factory its bus type registered
// (config/bus_types.hpp; the build's registry: daemon/bus_types.cpp).
#include <memory>

#include "config/plan.hpp"
#include "core/bus.hpp"

namespace drivegate::daemon {

// Throws core::BusError when the type has no adapter in this build.
std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan);

}  // namespace drivegate::daemon
