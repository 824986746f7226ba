#include "daemon/bus_factory.hpp"

#include "adapters/sim/sim_bus.hpp"

namespace drivegate::daemon {

std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan) {
  if (plan.type == "sim") return std::make_unique<sim::SimBus>(plan);
  throw core::BusError("bus '" + plan.name + "': type '" + plan.type + "' has no adapter in this build");
}

}  // namespace drivegate::daemon
