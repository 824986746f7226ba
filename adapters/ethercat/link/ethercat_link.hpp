#pragma once
// EtherCAT's link: the shared raw Ethernet link (adapters/link, DESIGN.md §5) with EtherCAT's frame
// rules built in, under the names the EtherCAT code uses. EtherCAT frames are Ethernet II frames of
// EtherType 88A4h (ETG.1000.4 §5.3: Ethernet header, then the 2-byte EtherCAT header, then the
// datagrams); masters send them untagged, so a tagged frame is a wrong EtherType here. Shorter than
// an Ethernet header plus the EtherCAT header cannot be an EtherCAT frame.
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>

#include "adapters/ethercat/wire/ethernet.hpp"
#include "adapters/link/memory_link.hpp"
#include "adapters/link/raw_socket_link.hpp"

namespace drivegate::ethercat {

inline constexpr link::FrameRules kFrameRules{.ether_type = kEtherType,
                                              .min_frame_bytes = kEthernetHeaderSize + kEcatHeaderSize,
                                              .vlan_tags = false,
                                              .name = "ethercat",
                                              .peers = "slaves"};
static_assert(kMaxFrameSize == link::kMaxUntaggedFrameBytes);

using link::FrameBuffer;
using link::FrameCheck;
using link::FrameSink;
using link::FrameView;
using link::kLinkBatch;
using link::Link;
using link::LinkCounters;
using link::LinkError;
using link::LinkState;
using link::RawSocketOptions;
using link::SendResult;
using link::SendStatus;

// check_frame() by EtherCAT's rules.
[[nodiscard]] inline FrameCheck check_frame(std::span<const std::uint8_t> frame) noexcept {
  return link::check_frame(frame, kFrameRules);
}

class MemoryLink final : public link::MemoryLink {
 public:
  explicit MemoryLink(std::size_t capacity = 256) : link::MemoryLink(kFrameRules, capacity) {}
};

class RawSocketLink final : public link::RawSocketLink {
 public:
  explicit RawSocketLink(RawSocketOptions options) : link::RawSocketLink(kFrameRules, std::move(options)) {}
};

}  // namespace drivegate::ethercat
