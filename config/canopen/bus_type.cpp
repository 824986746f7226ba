#include "config/canopen/bus_type.hpp"

#include "config/canopen/axis_section.hpp"
#include "config/canopen/bus_options.hpp"
#include "config/canopen/describe.hpp"
#include "config/canopen/device_section.hpp"
#include "config/canopen/parameters.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

// Drives that watch the gateway (heartbeat consumer 1016h, node guarding) fault when its cycle
// stalls: under load a normally scheduled cycle thread stalled for 390 ms and every drive faulted.
// Simulated drives (transport sim) run in the same thread and cannot notice.
void check_realtime(const BusPlan& bus, const BusEntry& at) {
  if (bus.priority > 0 || bus.section<CanopenBusOptions>().transport == CanTransportKind::Simulated) return;
  for (const auto& a : bus.axes) {
    const auto& dev = a.device.section<CanopenDeviceSpec>();
    if (dev.error_control != ErrorControl::Guarding && !dev.consumer_heartbeat) continue;
    at.source.warning(at.mark, at.path,
                      "bus \"" + bus.name + "\" runs without real-time priority, but its drives watch the gateway (axis \"" +
                          a.spec.name + "\": " + (dev.error_control == ErrorControl::Guarding ? "node guarding" : "heartbeat consumer 1016h") +
                          "): a cycle stalled by load faults them; give the bus a priority (1..99) and run drivegated as the "
                          "README's \"Deployment\" says");
    return;
  }
}

// Two gateways on one CAN interface or multicast group would fight over the drives.
std::string resource(const BusPlan& bus) {
  const auto& c = bus.section<CanopenBusOptions>();
  switch (c.transport) {
    case CanTransportKind::SocketCan: return "canopen socketcan " + c.interface;
    case CanTransportKind::UdpMulticast: return "canopen udp-multicast " + c.group + ":" + std::to_string(c.port);
    default: return {};
  }
}

}  // namespace

BusTypeInfo canopen_bus_type() {
  BusTypeInfo t;
  t.name = "canopen";
  t.min_address = 1;  // node-IDs 1..127 [CiA 301 §7.3.2]
  t.max_address = 127;
  t.axis_section = "canopen";
  t.address_words = "a CANopen node-ID";
  // SYNC period: 1 ms is the shortest cycle the reference drives run (SD6 A150: 1..8 ms,
  // stoeber-sd6-canopen.md §7; AKD ip/csp whole milliseconds, akd part 2 §15.16).
  t.min_cycle_time = 1ms;
  t.max_cycle_time = 1s;
  t.options = canopen_options();
  t.address_name = "node-ID";
  // Two drives on one node-ID answer each other's SDOs and PDOs: the message names both axes.
  t.reused_address_names_axes = true;
  t.device_section = "canopen";
  t.read_bus = read_canopen_bus;
  t.read_axis = read_canopen_axis;
  t.read_device = read_canopen_device;
  t.mapped_objects = canopen_mapped_objects;
  t.check_bus = {check_realtime};
  t.describe_bus = {describe_canopen_bus};
  t.describe_axis = describe_canopen_axis;
  t.find_parameter = find_canopen_parameter;
  t.resource = resource;
  return t;
}

}  // namespace drivegate::config
