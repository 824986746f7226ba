#include "adapters/ethercat/sim_transport.hpp"

#include "adapters/ethercat/sim/sim_personas.hpp"
#include "core/bus.hpp"

namespace drivegate::ethercat {

std::unique_ptr<EthercatBus> make_simulated_ethercat_bus(const config::BusPlan& plan) {
  std::shared_ptr<sim::BuiltLine> line;
  try {
    line = sim::build_line(plan, sim::PersonaRegistry::builtin());
  } catch (const std::exception& e) {
    throw core::BusError(e.what());
  }
  return std::make_unique<EthercatBus>(plan, std::make_unique<SimLineLink>(line), std::make_unique<SimLinePeer>(line));
}

}  // namespace drivegate::ethercat
