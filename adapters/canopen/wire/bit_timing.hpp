#pragma once
// How long a classic CAN frame occupies the bus, with worst-case bit stuffing: the basis of the
// bus-load estimate in --check-config and of the wire-emulating in-process bus.
//
// A data frame with n bytes has 34 + 8n (base) or 54 + 8n (extended) bits from SOF to the end of
// the CRC that are subject to stuffing, at worst one stuff bit per 4 after the first, plus 13 fixed
// bits (CRC delimiter, ACK slot and delimiter, 7 EOF) and 3 bits of interframe space [ISO 11898-1;
// e.g. 135 bits for 8 bytes base format]. A remote frame has no data field.
#include <cstdint>

#include "core/clock.hpp"

namespace drivegate::canopen {

constexpr std::uint32_t frame_bits(std::uint8_t dlc, bool extended = false, bool remote = false) noexcept {
  const std::uint32_t data_bits = remote ? 0U : 8U * (dlc > 8 ? 8U : dlc);
  const std::uint32_t stuffed = (extended ? 54U : 34U) + data_bits;
  return stuffed + (stuffed - 1U) / 4U + 13U;
}

constexpr core::Duration frame_time(std::uint8_t dlc, std::uint32_t bitrate, bool extended = false,
                                    bool remote = false) noexcept {
  if (bitrate == 0) return core::Duration::zero();
  return core::Duration(std::int64_t{frame_bits(dlc, extended, remote)} * 1'000'000'000 / bitrate);
}

static_assert(frame_bits(8) == 135);
static_assert(frame_bits(0) == 55);
static_assert(frame_bits(8, true) == 160);

}  // namespace drivegate::canopen
