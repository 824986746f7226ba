// The bus types of this build: each adapter's registration, and the types known without one. This
// is the one place that names every adapter; config/, the plan, the printout and the bus factory
// reach the bus types only through the registry (config/bus_types.hpp).
#include "adapters/canopen/bus_type.hpp"
#include "adapters/ethercat/bus_type.hpp"
#include "adapters/sim/bus_type.hpp"
#include "config/bus_types.hpp"

namespace drivegate::config {

namespace {

// A bus type a configuration may name, with no adapter in this build yet.
BusTypeInfo known(std::string name, std::int64_t max_address) {
  BusTypeInfo t;
  t.name = std::move(name);
  t.max_address = max_address;
  return t;
}

}  // namespace

BusTypeRegistry BusTypeRegistry::builtin() {
  BusTypeRegistry r;
  r.add(sim::bus_type());
  r.add(canopen::bus_type());
  r.add(ethercat::bus_type());
  // PROFINET device numbers.
  r.add(known("profinet", 65535));
  return r;
}

}  // namespace drivegate::config
