#include "adapters/sim/bus_type.hpp"

#include "adapters/sim/sim_bus.hpp"
#include "config/sim/bus_type.hpp"

namespace drivegate::sim {

config::BusTypeInfo bus_type() {
  config::BusTypeInfo t = config::sim_bus_type();
  t.make_bus = [](const config::BusPlan& plan) -> std::unique_ptr<core::Bus> { return std::make_unique<SimBus>(plan); };
  return t;
}

}  // namespace drivegate::sim
