#pragma once
// One classic CAN frame as every layer of the CANopen adapter sees it: transports fill it from the
// wire, engines read and produce it. Trivially copyable, fixed size, no allocation.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>

#include "core/bytes.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen {

inline constexpr std::uint32_t kMaxStandardId = 0x7FF;
inline constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFF;
inline constexpr std::uint8_t kMaxDlc = 8;

struct CanFrame {
  std::uint32_t id = 0;  // 11-bit, or 29-bit when `extended`
  std::uint8_t dlc = 0;  // 0..8; for a remote frame the requested length
  bool extended = false;
  bool remote = false;  // RTR
  std::array<std::uint8_t, 8> data{};
  core::TimePoint timestamp{};  // reception time (set by the transport); unused when sending

  // The data bytes (none for a remote frame; never more than 8, whatever dlc says).
  [[nodiscard]] std::span<const std::uint8_t> payload() const noexcept {
    return {data.data(), remote ? 0U : (dlc > kMaxDlc ? kMaxDlc : dlc)};
  }
  // A frame that can exist on a classic CAN bus.
  [[nodiscard]] constexpr bool valid() const noexcept {
    return dlc <= kMaxDlc && id <= (extended ? kMaxExtendedId : kMaxStandardId);
  }
};

// A standard data frame with the given bytes (at most 8 are taken).
inline CanFrame make_frame(std::uint32_t id, std::span<const std::uint8_t> bytes) noexcept {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size() > kMaxDlc ? kMaxDlc : bytes.size());
  for (std::size_t i = 0; i < f.dlc; ++i) f.data[i] = bytes[i];
  return f;
}

inline CanFrame make_frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) noexcept {
  return make_frame(id, std::span<const std::uint8_t>(bytes.begin(), bytes.size()));
}

// Little-endian helpers for CANopen payloads [CiA 301 §7.1: all numbers little-endian]: n bytes
// (at most 4) from / to offset `at`, never past the end of the span.
inline constexpr std::uint32_t get_le(std::span<const std::uint8_t> b, std::size_t at, std::size_t n) noexcept {
  return at < b.size() ? static_cast<std::uint32_t>(core::get_le(b.subspan(at, std::min({n, std::size_t{4}, b.size() - at})))) : 0;
}
inline constexpr void put_le(std::span<std::uint8_t> b, std::size_t at, std::size_t n, std::uint32_t v) noexcept {
  if (at < b.size()) core::put_le(b.subspan(at, std::min({n, std::size_t{4}, b.size() - at})), v);
}

}  // namespace drivegate::canopen
