#pragma once
// PROFINET's transports (adapters/link, DESIGN.md §5): raw Ethernet frames of EtherType 8892h (DCP,
// RT class 1 cyclic frames, alarms) on a link::RawSocketLink or link::MemoryLink with these frame
// rules, and DCE/RPC connection management over a link::UdpEndpoint on the interface's IPv4
// address (a link::MemoryDatagramPort pair in unit tests).
//
// RT cyclic and alarm frames carry an 802.1Q priority tag, DCP frames go untagged (wire/ethernet.hpp);
// the link hands up both as they were sent, so wire::decode_ethernet sees the tag and its priority.
#include <array>
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

// IPv4 addresses as the engines and the config hold them (host order, a.b.c.d = a << 24 | ...) and
// as the links and DCP blocks carry them (four octets in network order).
constexpr std::uint32_t ipv4_host(const std::array<std::uint8_t, 4>& a) noexcept {
  return std::uint32_t{a[0]} << 24 | std::uint32_t{a[1]} << 16 | std::uint32_t{a[2]} << 8 | a[3];
}
constexpr std::array<std::uint8_t, 4> ipv4_octets(std::uint32_t ip) noexcept {
  return {static_cast<std::uint8_t>(ip >> 24), static_cast<std::uint8_t>(ip >> 16), static_cast<std::uint8_t>(ip >> 8),
          static_cast<std::uint8_t>(ip)};
}

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
