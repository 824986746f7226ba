#include "daemon/bus_factory.hpp"

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/sim/sim_bus.hpp"

namespace drivegate::daemon {

std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan) {
  if (plan.type == "sim") return std::make_unique<sim::SimBus>(plan);
  if (plan.type == "canopen") {
    try {
      return canopen::make_canopen_bus(plan);
    } catch (const canopen::TransportError& e) {
      throw core::BusError(e.what());
    } catch (const std::invalid_argument& e) {  // a simulated drive refused its configuration
      throw core::BusError("bus '" + plan.name + "': " + e.what());
    }
  }
  throw core::BusError("bus '" + plan.name + "': type '" + plan.type + "' has no adapter in this build");
}

}  // namespace drivegate::daemon
