// The bus types of this build: each adapter's registration. This
// is the one place that names every adapter; config/, the plan, the printout and the bus factory
// reach the bus types only through the registry (config/bus_types.hpp).
#include "adapters/canopen/bus_type.hpp"
#include "adapters/ethercat/bus_type.hpp"
#include "adapters/profinet/bus_type.hpp"
#include "adapters/sim/bus_type.hpp"
#include "config/bus_types.hpp"

namespace drivegate::config {

BusTypeRegistry BusTypeRegistry::builtin() {
  BusTypeRegistry r;
  r.add(sim::bus_type());
  r.add(canopen::bus_type());
  r.add(ethercat::bus_type());
  r.add(profinet::bus_type());
  return r;
}

}  // namespace drivegate::config
