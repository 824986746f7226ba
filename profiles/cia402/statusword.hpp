#pragma once
// Pure decoding of statusword 6041h: the device-control state (masks per AKD digest §1, identical in
// NORD digest §3.3) and the flag bits.
#include <cstdint>

#include "core/axis_types.hpp"

namespace drivegate::cia402 {

namespace sw {
inline constexpr std::uint16_t kReadyToSwitchOn = 1U << 0;
inline constexpr std::uint16_t kSwitchedOn = 1U << 1;
inline constexpr std::uint16_t kOperationEnabled = 1U << 2;
inline constexpr std::uint16_t kFault = 1U << 3;
inline constexpr std::uint16_t kVoltageEnabled = 1U << 4;
inline constexpr std::uint16_t kQuickStop = 1U << 5;  // active low: 0 = quick stop active
inline constexpr std::uint16_t kSwitchOnDisabled = 1U << 6;
inline constexpr std::uint16_t kWarning = 1U << 7;
inline constexpr std::uint16_t kManufacturer8 = 1U << 8;  // AKD: STO; NORD: P481 function
inline constexpr std::uint16_t kRemote = 1U << 9;
inline constexpr std::uint16_t kTargetReached = 1U << 10;
inline constexpr std::uint16_t kInternalLimit = 1U << 11;
// Bits 12/13 depend on the mode [AKD digest §3.4]: pp set-point acknowledge / following error,
// hm homing attained / homing error, ip active / following error, csp following / following error.
inline constexpr std::uint16_t kModeBit12 = 1U << 12;
inline constexpr std::uint16_t kModeBit13 = 1U << 13;
inline constexpr std::uint16_t kSetpointAcknowledge = kModeBit12;
inline constexpr std::uint16_t kHomingAttained = kModeBit12;
inline constexpr std::uint16_t kFollowingError = kModeBit13;
inline constexpr std::uint16_t kHomingError = kModeBit13;
}  // namespace sw

// AxisState::Unknown for bit patterns CiA 402 does not define.
core::AxisState decode_state(std::uint16_t statusword) noexcept;

struct StatusFlags {
  bool voltage_enabled = false;
  bool warning = false;
  bool remote = false;
  bool target_reached = false;
  bool internal_limit = false;
  bool bit12 = false;  // meaning depends on the mode (see sw::kModeBit12)
  bool bit13 = false;
};

StatusFlags decode_flags(std::uint16_t statusword) noexcept;

}  // namespace drivegate::cia402
