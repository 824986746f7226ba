#pragma once
// Builds the Bus implementation for a compiled bus plan. Each adapter registers its bus type here;
// the config's BusTypeRegistry lists which types and options the file may use.
#include <memory>

#include "config/plan.hpp"
#include "core/bus.hpp"

namespace drivegate::daemon {

// Throws core::BusError when the type has no adapter in this build.
std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan);

}  // namespace drivegate::daemon
