// Building a CANopen bus from a plan: its transport, and for `transport: sim` the simulated
// drives on an in-process wire.
#include <memory>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/sim/sim_network.hpp"
#include "adapters/canopen/transport/socketcan_transport.hpp"
#include "adapters/canopen/transport/udp_multicast_transport.hpp"

namespace drivegate::canopen {

std::unique_ptr<Transport> make_transport(const config::BusPlan& plan) {
  const auto& o = plan.section<config::CanopenBusOptions>();
  switch (o.transport) {
    case config::CanTransportKind::SocketCan: {
      SocketCanOptions s;
      s.interface = o.interface;
      s.bitrate = o.bitrate;
      // Every frame of a configured node (any function code; mask on the node-ID bits), plus the
      // extra SDO channels whose COB-IDs carry the channel in the node field (SD6 §5.3).
      for (const auto& a : plan.axes) {
        const auto node = static_cast<NodeId>(a.address);
        s.filters.push_back({node, 0x7F, false});
        const int ch = a.section<config::CanopenAxisOptions>().sdo_channel;
        if (ch > 1) s.filters.push_back({cob::sdo_tx(ch, node), kMaxStandardId, false});
      }
      return std::make_unique<SocketCanTransport>(std::move(s));
    }
    case config::CanTransportKind::UdpMulticast: {
      UdpMulticastOptions u;
      u.group = o.group;
      u.port = static_cast<std::uint16_t>(o.port);
      u.interface_address = o.interface;
      return std::make_unique<UdpMulticastTransport>(std::move(u));
    }
    case config::CanTransportKind::Simulated: break;
  }
  throw TransportError("bus '" + plan.name + "': transport sim has no stand-alone transport");
}

}  // namespace drivegate::canopen

namespace drivegate::canopen {

std::unique_ptr<CanopenBus> make_canopen_bus(const config::BusPlan& plan) {
  if (plan.section<config::CanopenBusOptions>().transport == config::CanTransportKind::Simulated) {
    auto wiring = sim::SimPeer::wire(plan);
    return std::make_unique<CanopenBus>(plan, std::move(wiring.gateway), std::move(wiring.peer));
  }
  return std::make_unique<CanopenBus>(plan, make_transport(plan));
}

}  // namespace drivegate::canopen
