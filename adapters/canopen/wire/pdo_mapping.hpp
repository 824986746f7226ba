#pragma once
// PDO mapping entries (1600h../1A00h.. sub 1..n): index << 16 | sub << 8 | length in bits
// [CiA 301 §7.5.2.36; AKD part 1 §12.3; NORD TV-A]. Only byte-granular objects are mapped here
// (every reference drive maps whole bytes only: AKD quirk 9).
#include <cstdint>

#include "profiles/cia402/objects.hpp"

namespace drivegate::canopen {

struct MappingEntry {
  cia402::ObjectId object{};
  std::uint8_t bits = 0;
  friend constexpr bool operator==(MappingEntry a, MappingEntry b) noexcept {
    return a.object == b.object && a.bits == b.bits;
  }
};

constexpr std::uint32_t encode_mapping(MappingEntry e) noexcept {
  return (std::uint32_t{e.object.index} << 16) | (std::uint32_t{e.object.sub} << 8) | e.bits;
}
constexpr MappingEntry decode_mapping(std::uint32_t v) noexcept {
  return {{static_cast<std::uint16_t>(v >> 16), static_cast<std::uint8_t>((v >> 8) & 0xFF)},
          static_cast<std::uint8_t>(v & 0xFF)};
}

static_assert(encode_mapping({{0x6041, 0}, 16}) == 0x60410010);
static_assert(decode_mapping(0x60FF0020) == MappingEntry{{0x60FF, 0}, 32});

// Communication parameter indices [CiA 301 §7.5.2.35]: RPDO n at 1400h+n / 1600h+n, TPDO n at
// 1800h+n / 1A00h+n (n = 0..3 here; the reference drives have four of each).
constexpr std::uint16_t rpdo_comm_index(int pdo) noexcept { return static_cast<std::uint16_t>(0x1400 + pdo); }
constexpr std::uint16_t rpdo_map_index(int pdo) noexcept { return static_cast<std::uint16_t>(0x1600 + pdo); }
constexpr std::uint16_t tpdo_comm_index(int pdo) noexcept { return static_cast<std::uint16_t>(0x1800 + pdo); }
constexpr std::uint16_t tpdo_map_index(int pdo) noexcept { return static_cast<std::uint16_t>(0x1A00 + pdo); }

}  // namespace drivegate::canopen
