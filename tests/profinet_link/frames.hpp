#pragma once
// PROFINET test frames built with the wire codec (wire/ethernet.hpp), and the helpers the link tests
// share.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "adapters/link/link.hpp"
#include "adapters/profinet/wire/ethernet.hpp"

namespace drivegate::profinet::test {

// A `size`-byte frame (at least the header) with FrameID `frame_id`, from 02:00:00:00:00:01 to
// 02:00:00:00:00:02; tagged with `priority`/`vlan_id` when `tagged`; the PDU counts up from `seed`.
// `ether_type` replaces 8892h behind the (optional) tag.
inline std::vector<std::uint8_t> make_frame(std::uint16_t frame_id, bool tagged, std::size_t size = 60,
                                            std::uint8_t priority = kPriorityRtCyclic, std::uint16_t vlan_id = 0,
                                            std::uint16_t ether_type = kEtherType, std::uint8_t seed = 0) {
  std::vector<std::uint8_t> f(std::max<std::size_t>(size, 20), 0);  // the header, then cut to `size`
  EthernetHeader h;
  h.dst = {0x02, 0, 0, 0, 0, 0x02};
  h.src = {0x02, 0, 0, 0, 0, 0x01};
  h.vlan = tagged;
  h.priority = priority;
  h.vlan_id = vlan_id;
  h.frame_id = frame_id;
  const std::size_t pdu = encode_ethernet_header(h, f);
  const std::size_t type_at = tagged ? 16 : 12;
  f[type_at] = static_cast<std::uint8_t>(ether_type >> 8);
  f[type_at + 1] = static_cast<std::uint8_t>(ether_type & 0xFF);
  for (std::size_t i = pdu; i < size; ++i) f[i] = static_cast<std::uint8_t>(seed + i);
  f.resize(size);
  return f;
}

inline std::vector<std::uint8_t> bytes_of(const link::FrameBuffer& b) {
  return {b.bytes.begin(), b.bytes.begin() + static_cast<std::ptrdiff_t>(b.size)};
}

}  // namespace drivegate::profinet::test
