#pragma once
// Controlword 6040h values and bits the master sends [AKD digest §1 and §3.3; NORD digest §3.2/§3.4].
#include <cstdint>

namespace drivegate::cia402::cw {

// Device-control commands (bits 7, 3, 2, 1, 0) with the don't-care bits at 0 [AKD digest §1].
inline constexpr std::uint16_t kDisableVoltage = 0x0000;  // transitions 7, 9, 10, 12
inline constexpr std::uint16_t kQuickStop = 0x0002;       // transitions 7, 10, 11
inline constexpr std::uint16_t kShutdown = 0x0006;        // transitions 2, 6, 8
inline constexpr std::uint16_t kSwitchOn = 0x0007;        // transition 3 (also disable operation, 5)
inline constexpr std::uint16_t kEnableOperation = 0x000F; // transitions 4, 16

// Bits 0..3: the part of the controlword that selects the device-control command.
inline constexpr std::uint16_t kDeviceControlMask = 0x000F;
// Bits 4..6 are mode specific [AKD digest §3.3]: pp new set-point / change immediately / relative,
// hm homing start, ip enable interpolation; NORD vl: bus set-point, ramp enable, set-point enable.
inline constexpr std::uint16_t kNewSetpoint = 1U << 4;
inline constexpr std::uint16_t kHomingStart = 1U << 4;
inline constexpr std::uint16_t kEnableInterpolation = 1U << 4;
inline constexpr std::uint16_t kChangeImmediately = 1U << 5;
inline constexpr std::uint16_t kRelative = 1U << 6;
inline constexpr std::uint16_t kModeBitsMask = 0x0070;
// NORD vl needs bits 4..6 all set to run from the bus set-point: 0x007F [NORD digest §5.2].
inline constexpr std::uint16_t kVlRunBits = 0x0070;
// Fault reset acts on the 0->1 edge of bit 7 [AKD digest §3.7 item 3; NORD digest §3.2 #15].
inline constexpr std::uint16_t kFaultReset = 1U << 7;
// Halt: stop in every mode, keep the set-points [AKD digest §3.3].
inline constexpr std::uint16_t kHalt = 1U << 8;

constexpr std::uint16_t with(std::uint16_t base, std::uint16_t bits, bool on) noexcept {
  return static_cast<std::uint16_t>(on ? (base | bits) : (base & ~bits));
}

}  // namespace drivegate::cia402::cw
