#pragma once
// Test frames for the link tests. The link does not interpret anything past the Ethernet header, so
// the payload is a counting pattern behind an EtherCAT frame header, not a real datagram.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"

namespace drivegate::ethercat::test {

// A `size`-byte Ethernet frame: broadcast destination, source 02:00:00:00:00:01 (a locally
// administered address), EtherType `ethertype` (big-endian, IEEE 802.3 §3.2.6), then the EtherCAT
// header (ETG.1000.4: length in bits 0-10, type 1 = datagrams in bits 12-15, little-endian) and the
// bytes tag, tag+1, ...
inline std::vector<std::uint8_t> make_frame(std::uint8_t tag, std::size_t size = 60,
                                            std::uint16_t ethertype = kEtherType) {
  std::vector<std::uint8_t> f(size, 0);
  for (std::size_t i = 0; i < 6 && i < size; ++i) f[i] = 0xFF;
  const std::uint8_t source[6] = {0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
  for (std::size_t i = 0; i < 6 && 6 + i < size; ++i) f[6 + i] = source[i];
  if (size >= 14) {
    f[12] = static_cast<std::uint8_t>(ethertype >> 8);
    f[13] = static_cast<std::uint8_t>(ethertype & 0xFF);
  }
  if (size >= 16) {
    const auto length = static_cast<std::uint16_t>((size - 16) & 0x7FF);
    const auto header = static_cast<std::uint16_t>(length | 0x1000);
    f[14] = static_cast<std::uint8_t>(header & 0xFF);
    f[15] = static_cast<std::uint8_t>(header >> 8);
  }
  for (std::size_t i = 16; i < size; ++i) f[i] = static_cast<std::uint8_t>(tag + (i - 16));
  return f;
}

inline std::vector<std::uint8_t> bytes_of(const FrameBuffer& b) { return {b.bytes.begin(), b.bytes.begin() + static_cast<std::ptrdiff_t>(b.size)}; }

}  // namespace drivegate::ethercat::test
