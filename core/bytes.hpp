#pragma once
// Fixed-width byte order access for the wire codecs. Fieldbus numbers are little-endian on the
// wire [ETG.1000.4 §5: octets are transferred LSB first; CiA 301 §7.1], the Ethernet EtherType is
// big-endian [IEEE 802.3 §3.2.6]. Callers check the span size first; these helpers do no bounds
// checks of their own beyond what std::span's operator[] implies.
#include <cstddef>
#include <cstdint>
#include <span>

namespace drivegate::core {

inline std::uint16_t get_u16(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}
inline std::uint32_t get_u32(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
         (static_cast<std::uint32_t>(b[at + 2]) << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}
inline std::uint64_t get_u64(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return static_cast<std::uint64_t>(get_u32(b, at)) | (static_cast<std::uint64_t>(get_u32(b, at + 4)) << 32);
}
inline void put_u16(std::span<std::uint8_t> b, std::size_t at, std::uint16_t v) noexcept {
  b[at] = static_cast<std::uint8_t>(v & 0xFF);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::span<std::uint8_t> b, std::size_t at, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFF);
}
inline void put_u64(std::span<std::uint8_t> b, std::size_t at, std::uint64_t v) noexcept {
  for (std::size_t i = 0; i < 8; ++i) b[at + i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFF);
}

// Every byte of `b` (at most 8) as one little-endian number, and `v` into every byte of `b`.
constexpr std::uint64_t get_le(std::span<const std::uint8_t> b) noexcept {
  std::uint64_t v = 0;
  for (std::size_t i = b.size() < 8 ? b.size() : 8; i-- > 0;) v = (v << 8) | b[i];
  return v;
}
constexpr void put_le(std::span<std::uint8_t> b, std::uint64_t v) noexcept {
  for (std::size_t i = 0; i < b.size() && i < 8; ++i) b[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// Big-endian 16 bits (the EtherType and the 802.1Q tag).
inline std::uint16_t get_be16(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}
inline void put_be16(std::span<std::uint8_t> b, std::size_t at, std::uint16_t v) noexcept {
  b[at] = static_cast<std::uint8_t>(v >> 8);
  b[at + 1] = static_cast<std::uint8_t>(v & 0xFF);
}

}  // namespace drivegate::core
