#pragma once
// PROFINET's transports (adapters/link, DESIGN.md §5): raw Ethernet frames of EtherType 8892h (DCP,
// RT class 1 cyclic frames, alarms) on a link::RawSocketLink or link::MemoryLink with these frame
// rules, and DCE/RPC connection management over a link::UdpEndpoint on the interface's IPv4
// address (a link::MemoryDatagramPort pair in unit tests).
//
// RT cyclic and alarm frames carry an 802.1Q priority tag, DCP frames go untagged (wire/ethernet.hpp);
// the link hands up both as they were sent, so wire::decode_ethernet sees the tag and its priority.
#include <cstdint>
#include <string>
#include <utility>

#include "adapters/link/link.hpp"
#include "adapters/link/udp_endpoint.hpp"
#include "adapters/profinet/wire/ethernet.hpp"

namespace drivegate::profinet {

// The shortest PROFINET frame carries a FrameID after the Ethernet header.
inline constexpr link::FrameRules kFrameRules{.ether_type = kEtherType,
                                              .min_frame_bytes = kEthernetHeaderSize + kFrameIdSize,
                                              .vlan_tags = true,
                                              .name = "profinet",
                                              .peers = "devices"};
static_assert(kMaxFrameSize == link::kMaxFrameBytes && kVlanTpid == link::kVlanTpid);

// The UDP endpoint for DCE/RPC on `interface`: a controller's with port 0 (the kernel picks one; it
// sends to the device's wire/rpc.hpp kRpcUdpPort), a device's (or a simulated one's) with kRpcUdpPort.
inline link::UdpOptions rpc_udp_options(std::string interface, std::uint16_t port = 0) {
  link::UdpOptions o;
  o.interface = std::move(interface);
  o.port = port;
  o.name = kFrameRules.name;
  o.peers = kFrameRules.peers;
  return o;
}

}  // namespace drivegate::profinet
