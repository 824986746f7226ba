#include "config/profinet/bus_type.hpp"

#include "config/profinet/axis_section.hpp"
#include "config/profinet/bus_options.hpp"
#include "config/profinet/describe.hpp"
#include "config/profinet/device_section.hpp"
#include "config/profinet/parameters.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

// Two controllers on one Ethernet interface would both send the stations' frames.
std::string resource(const BusPlan& bus) {
  const auto& c = bus.section<ProfinetBusOptions>();
  return c.simulated ? std::string{} : "profinet " + c.interface;
}

}  // namespace

BusTypeInfo profinet_bus_type(const ProfinetWireRules& rules) {
  BusTypeInfo t;
  t.name = "profinet";
  // The station name addresses a drive; the address numbers the axes of the bus.
  t.min_address = 1;
  t.max_address = 65535;
  t.address_words = "an axis number of the bus (1..65535; the drive is profinet.station)";
  // cycle_time is the send clock, 31.25 us x 2^n: 250 us is the shortest a user-space controller
  // keeps, 4 ms the longest RT class 1 send clock [IEC 61158-6-10, SendClockFactor 1..128].
  t.min_cycle_time = 250us;
  t.max_cycle_time = 4ms;
  t.options = profinet_options();
  t.bus_keys = {"devices", "io"};
  t.axis_section = "profinet";
  t.device_section = "profidrive";
  t.cia402_device = false;
  t.read_bus = [rules](const MapReader& b, const MapReader& m, BusPlan& bus) { read_profinet_bus(rules, b, m, bus); };
  t.read_axis = read_profinet_axis;
  t.read_device = read_profidrive_device;
  t.check_bus = {check_profinet_stations};
  t.describe_bus = {[rules](const BusPlan& bus, DescribeRows& rows) { describe_profinet_bus(rules, bus, rows); }};
  t.describe_axis = describe_profinet_axis;
  t.find_parameter = find_profidrive_parameter;
  t.resource = resource;
  return t;
}

}  // namespace drivegate::config
