#include "config/ethercat/bus_type.hpp"

#include "config/ethercat/axis_section.hpp"
#include "config/ethercat/bus_options.hpp"
#include "config/ethercat/device_section.hpp"
#include "config/ethercat/parameters.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

// Two gateways on one Ethernet interface would both send the line's frames.
std::string resource(const BusPlan& bus) {
  const auto& c = bus.section<EthercatBusOptions>();
  return c.transport == EthercatTransportKind::Raw ? "ethercat " + c.interface : std::string{};
}

}  // namespace

BusTypeInfo ethercat_bus_type() {
  BusTypeInfo t;
  t.name = "ethercat";
  // Positions on the line, 1 = the slave next to the gateway; the configured station address is
  // derived from them (1000h + position).
  t.min_address = 1;
  t.max_address = 65535;
  t.address_words = "a position on the EtherCAT line (1 = the slave next to the gateway)";
  t.address_name = "position";
  t.reused_address_names_axes = true;
  t.address_key = ethercat_address_key;
  // 125 us is the shortest cycle ETG.1020 drives commonly take; the SM watchdog bounds the longest.
  t.min_cycle_time = 125us;
  t.max_cycle_time = 100ms;
  t.options = ethercat_options();
  t.bus_keys = {"io"};
  t.axis_section = "ethercat";
  t.device_section = "ethercat";
  t.read_bus = read_ethercat_bus;
  t.read_axis = read_ethercat_axis;
  t.read_device = read_ethercat_device;
  t.mapped_objects = ethercat_mapped_objects;
  t.check_bus = {check_ethercat_slaves};
  t.resource = resource;
  t.find_parameter = find_ethercat_parameter;
  return t;
}

}  // namespace drivegate::config
