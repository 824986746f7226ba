#pragma once
// EMCY frames on 080h+n: error code (U16), error register (1001h), five manufacturer bytes
// [CiA 301 §7.2.7.3.1]. The manufacturer bytes carry vendor data: STÖBER puts the event number
// E82 in byte 3 and the cause E43 in byte 4 (SD6 digest §6.9); the AKD puts a category in byte 3
// (AKD part 1 §9.1, quirk 5).
#include <array>
#include <cstdint>
#include <optional>
#include <span>

namespace drivegate::canopen {

struct Emcy {
  std::uint16_t code = 0;
  std::uint8_t error_register = 0;
  std::array<std::uint8_t, 5> vendor{};
};

// CiA 301 frames are 8 bytes; shorter frames that still hold the code and register are accepted
// (missing vendor bytes read as 0) because manuals show 7-byte EMCYs (AKD part 2 §13 item 32).
inline std::optional<Emcy> decode_emcy(std::span<const std::uint8_t> p) noexcept {
  if (p.size() < 3 || p.size() > 8) return std::nullopt;
  Emcy e;
  e.code = static_cast<std::uint16_t>(p[0] | (p[1] << 8));
  e.error_register = p[2];
  for (std::size_t i = 3; i < p.size(); ++i) e.vendor[i - 3] = p[i];
  return e;
}

inline std::array<std::uint8_t, 8> encode_emcy(const Emcy& e) noexcept {
  std::array<std::uint8_t, 8> b{};
  b[0] = static_cast<std::uint8_t>(e.code & 0xFF);
  b[1] = static_cast<std::uint8_t>(e.code >> 8);
  b[2] = e.error_register;
  for (std::size_t i = 0; i < 5; ++i) b[3 + i] = e.vendor[i];
  return b;
}

}  // namespace drivegate::canopen
