#pragma once
// Big-endian field access for the PROFINET Ethernet protocols: DCP, the RT APDU status, RTA and
// the alarm blocks carry every multi-octet number most significant octet first (IEC 61158-6-10
// codes them as Unsigned16/32 in network byte order; Wireshark's PN dissectors read them so),
// unlike the little-endian fieldbus numbers core/bytes.hpp serves. Callers check the span size first.
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/bytes.hpp"

namespace drivegate::profinet {

using core::get_be16;
using core::put_be16;

inline std::uint32_t get_be32(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return (static_cast<std::uint32_t>(b[at]) << 24) | (static_cast<std::uint32_t>(b[at + 1]) << 16) |
         (static_cast<std::uint32_t>(b[at + 2]) << 8) | static_cast<std::uint32_t>(b[at + 3]);
}
inline void put_be32(std::span<std::uint8_t> b, std::size_t at, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (24 - 8 * i));
}

}  // namespace drivegate::profinet
