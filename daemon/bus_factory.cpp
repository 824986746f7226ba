#include "daemon/bus_factory.hpp"

#include "config/bus_types.hpp"

namespace drivegate::daemon {

std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan) {
  if (plan.type_info && plan.type_info->make_bus) return plan.type_info->make_bus(plan);
  throw core::BusError("bus '" + plan.name + "': type '" + plan.type + "' has no adapter in this build");
}

}  // namespace drivegate::daemon
