#pragma once
// AKD PROFIdrive normalisation [akd-profinet-profidrive.md §17, §25.1..§25.5], in two layers:
//
// 1. Physical helpers with the manual's numbers: NSOLL_A/NIST_A 2^15 = 12000 rpm (signed 16 bit),
//    MDI_VELOCITY 2^32 = 12000 rpm, MDI_ACC/MDI_DEC 2^16 = 50 000 000 rpm/s (PNU 1008 may change
//    that), positions 2^(PNU 1002) counts per motor revolution (default 16 -> 65536), current
//    2^14 = DRV.IPEAK. Used for the plan printout, diagnostics and tests.
//
// 2. The project converts user units in one place, core/units.hpp (DESIGN.md §4): a device profile
//    declares the drive's native units (core::NativeUnits) and AxisRunner hands the profile drive
//    units (DriveCommand, int32/uint32). For the AKD over PROFIdrive those native units are
//    `native_units()` below, and the profile maps them onto the signals with the *_from_native
//    functions, which refuse what a signal cannot hold. One native velocity unit serves both
//    NSOLL_A and MDI_VELOCITY: 2^31 = 12000 rpm, so a signed int32 spans the AKD's whole speed range,
//    NSOLL_A = native / 2^16 and MDI_VELOCITY = native x 2.
#include <cstdint>
#include <optional>

#include "core/units.hpp"

namespace drivegate::profidrive {

inline constexpr double kAkdMaxSpeedRpm = 12000.0;         // 100 % speed [§17.1]
inline constexpr double kNsollFullScale = 32768.0;         // 2^15 [§17.1]
inline constexpr double kMdiVelocityFullScale = 4294967296.0;  // 2^32 [§17.1]
inline constexpr double kMdiAccFullScale = 65536.0;        // 2^16 [§17.3]
inline constexpr double kMdiAccDefaultRpmPerS = 50e6;      // rpm/s at 2^16 [§17.3]
inline constexpr double kCurrentFullScale = 16384.0;       // 2^14 = DRV.IPEAK [§17.4]
inline constexpr unsigned kDefaultSingleTurnBits = 16;     // PNU 1002 default [§17.2]

// --- Physical helpers -------------------------------------------------------------------------

// rpm -> NSOLL_A, rounded to nearest (the manual truncates: 60 rpm = 163.84 -> "163" [§17.1]).
// nullopt when it does not fit int16 (|rpm| beyond about 12000) or is not finite.
std::optional<std::int16_t> nsoll_from_rpm(double rpm) noexcept;
// The same, clamped to -32768..32767 (NaN gives 0).
std::int16_t nsoll_from_rpm_saturating(double rpm) noexcept;
double rpm_from_speed_word(std::int16_t raw) noexcept;  // NSOLL_A and NIST_A [§17.1, INF for NIST_A]

// rpm -> MDI_VELOCITY, 0 <= rpm < 12000 (2^32 itself is not representable [§17.1]).
std::optional<std::uint32_t> mdi_velocity_from_rpm(double rpm) noexcept;
double rpm_from_mdi_velocity(std::uint32_t raw) noexcept;

// rpm/s -> MDI_ACC/MDI_DEC for a full scale (rpm/s at 2^16, default 50e6). nullopt for values the
// 16-bit word cannot hold, negatives and values that round to 0 (the drive would not move).
std::optional<std::uint16_t> mdi_acc_from_rpm_per_s(double rpm_per_s,
                                                    double full_scale_rpm_per_s = kMdiAccDefaultRpmPerS) noexcept;
double rpm_per_s_from_mdi_acc(std::uint16_t raw, double full_scale_rpm_per_s = kMdiAccDefaultRpmPerS) noexcept;
// PNU 1008 read as "the rpm/s that 100 % stands for, in steps of 50e6/2^16 = 762.94 rpm/s", the
// second reading of the manual's table [§17.3, marked ?: verify on hardware]. 0 gives nullopt.
std::optional<double> acc_full_scale_from_pnu1008(std::uint16_t pnu1008) noexcept;

// Position counts per motor revolution from PNU 1002 (1..31 single-turn bits) [§17.2].
std::optional<double> counts_per_rev(unsigned single_turn_bits) noexcept;

// ITIST_GLATT -> amperes with the drive's peak current DRV.IPEAK [§17.4]: -182 at 9 A = -0.09998 A.
double amps_from_current_word(std::int16_t raw, double peak_current_a) noexcept;

// --- Native units for core/units.hpp -----------------------------------------------------------

struct AkdScaling {
  unsigned single_turn_bits = kDefaultSingleTurnBits;     // PNU 1002
  double acc_full_scale_rpm_per_s = kMdiAccDefaultRpmPerS;  // rpm/s at MDI_ACC = 2^16 (PNU 1008)
  double peak_current_a = 0;   // DRV.IPEAK; 0 = unknown
  double rated_current_a = 0;  // the motor's continuous (rated-torque) current; 0 = unknown
};

// Drive units per motor rev, rev/s, rev/s^2 and per rated torque for an AKD axis:
//   position     2^single_turn_bits              (MDI_TARPOS, XIST_A, HOME_DIST as they are)
//   velocity     2^31 / 200 = 10 737 418.24      (2^31 = 12000 rpm = 200 rev/s)
//   acceleration 2^16 / (full scale / 60)        (MDI_ACC units; 0.0786432 by default)
//   torque       16384 x rated / peak current    (ITIST_GLATT units), only when both are known
// nullopt when single_turn_bits or the full scale is out of range.
std::optional<core::NativeUnits> native_units(const AkdScaling& s) noexcept;
inline constexpr double kNativeVelocityPerRps = 2147483648.0 / 200.0;

// Native drive units (DriveCommand/DriveFeedback) <-> signal words.
std::optional<std::int16_t> nsoll_from_native(std::int32_t velocity) noexcept;  // rounds /2^16; refuses 2^15
std::int32_t native_from_nist(std::int16_t raw) noexcept;                      // x 2^16
std::optional<std::uint32_t> mdi_velocity_from_native(std::uint32_t velocity) noexcept;  // x 2; refuses >= 2^31
std::optional<std::uint16_t> mdi_acc_from_native(std::uint32_t acceleration) noexcept;   // refuses > 0xFFFF

}  // namespace drivegate::profidrive
