#include "config/ethercat/bus_type.hpp"

#include "config/ethercat/device_section.hpp"

namespace drivegate::config {

BusTypeInfo ethercat_bus_type() {
  BusTypeInfo t;
  t.name = "ethercat";
  // Positions on the line; the configured station address is derived from them.
  t.min_address = 1;
  t.max_address = 65535;
  t.device_section = "ethercat";
  t.read_device = read_ethercat_device;
  t.mapped_objects = ethercat_mapped_objects;
  return t;
}

}  // namespace drivegate::config
