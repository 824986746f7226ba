#pragma once
// CiA 402 (IEC 61800-7-201) objects the master profile and the drive model use, with their data
// types. Indices and types follow the standard; the reference digests confirm them per vendor
// (e.g. akd-canopen-part2-ds402.md §1 and §11.5).
#include <cstdint>

namespace drivegate::cia402 {

enum class DataType : std::uint8_t { I8, U8, I16, U16, I32, U32 };

constexpr std::uint8_t size_of(DataType t) noexcept {
  switch (t) {
    case DataType::I8:
    case DataType::U8: return 1;
    case DataType::I16:
    case DataType::U16: return 2;
    case DataType::I32:
    case DataType::U32: return 4;
  }
  return 4;
}
constexpr bool is_signed(DataType t) noexcept {
  return t == DataType::I8 || t == DataType::I16 || t == DataType::I32;
}
// A value as the type holds it: truncated to the type's width and sign-extended when signed (what
// the little-endian bytes of a PDO or SDO transfer of that type mean).
constexpr std::int64_t normalise(DataType t, std::int64_t value) noexcept {
  const unsigned bits = 8U * size_of(t);
  const auto mask = (std::uint64_t{1} << bits) - 1U;
  const auto raw = static_cast<std::uint64_t>(value) & mask;
  if (is_signed(t) && (raw >> (bits - 1U)) != 0U) return static_cast<std::int64_t>(raw | ~mask);
  return static_cast<std::int64_t>(raw);
}
static_assert(normalise(DataType::I16, 0xFEF6) == -266);  // AKD part 1 §14 vector 2
static_assert(normalise(DataType::U8, 0x1FF) == 0xFF);

struct ObjectId {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  friend constexpr bool operator==(ObjectId a, ObjectId b) noexcept { return a.index == b.index && a.sub == b.sub; }
  [[nodiscard]] constexpr std::uint32_t key() const noexcept { return (std::uint32_t{index} << 8) | sub; }
};

struct ObjectDef {
  ObjectId id;
  DataType type;
};

namespace obj {
// Communication profile objects the profile reads.
inline constexpr ObjectDef kErrorRegister{{0x1001, 0}, DataType::U8};
// Device control [CiA 402 §6.3; AKD digest §3.3-3.6].
inline constexpr ObjectDef kErrorCode{{0x603F, 0}, DataType::U16};
inline constexpr ObjectDef kControlword{{0x6040, 0}, DataType::U16};
inline constexpr ObjectDef kStatusword{{0x6041, 0}, DataType::U16};
inline constexpr ObjectDef kVlTargetVelocity{{0x6042, 0}, DataType::I16};
inline constexpr ObjectDef kVlVelocityDemand{{0x6043, 0}, DataType::I16};
inline constexpr ObjectDef kVlVelocityActual{{0x6044, 0}, DataType::I16};
inline constexpr ObjectDef kVlAccelerationDeltaSpeed{{0x6048, 1}, DataType::U32};
inline constexpr ObjectDef kVlAccelerationDeltaTime{{0x6048, 2}, DataType::U16};
inline constexpr ObjectDef kVlDecelerationDeltaSpeed{{0x6049, 1}, DataType::U32};
inline constexpr ObjectDef kVlDecelerationDeltaTime{{0x6049, 2}, DataType::U16};
inline constexpr ObjectDef kQuickStopOption{{0x605A, 0}, DataType::I16};
inline constexpr ObjectDef kShutdownOption{{0x605B, 0}, DataType::I16};
inline constexpr ObjectDef kDisableOperationOption{{0x605C, 0}, DataType::I16};
inline constexpr ObjectDef kHaltOption{{0x605D, 0}, DataType::I16};
inline constexpr ObjectDef kFaultReactionOption{{0x605E, 0}, DataType::I16};
inline constexpr ObjectDef kModesOfOperation{{0x6060, 0}, DataType::I8};
inline constexpr ObjectDef kModesOfOperationDisplay{{0x6061, 0}, DataType::I8};
// Position, velocity, torque.
inline constexpr ObjectDef kPositionDemand{{0x6062, 0}, DataType::I32};
inline constexpr ObjectDef kPositionActual{{0x6064, 0}, DataType::I32};
inline constexpr ObjectDef kFollowingErrorWindow{{0x6065, 0}, DataType::U32};
inline constexpr ObjectDef kFollowingErrorTimeout{{0x6066, 0}, DataType::U16};
inline constexpr ObjectDef kPositionWindow{{0x6067, 0}, DataType::U32};
inline constexpr ObjectDef kPositionWindowTime{{0x6068, 0}, DataType::U16};
inline constexpr ObjectDef kVelocityActual{{0x606C, 0}, DataType::I32};
inline constexpr ObjectDef kVelocityWindow{{0x606D, 0}, DataType::U16};
inline constexpr ObjectDef kVelocityWindowTime{{0x606E, 0}, DataType::U16};
inline constexpr ObjectDef kTargetTorque{{0x6071, 0}, DataType::I16};
inline constexpr ObjectDef kMaxTorque{{0x6072, 0}, DataType::U16};
inline constexpr ObjectDef kTorqueActual{{0x6077, 0}, DataType::I16};
inline constexpr ObjectDef kTargetPosition{{0x607A, 0}, DataType::I32};
inline constexpr ObjectDef kHomeOffset{{0x607C, 0}, DataType::I32};
inline constexpr ObjectDef kSoftwareLimitMin{{0x607D, 1}, DataType::I32};
inline constexpr ObjectDef kSoftwareLimitMax{{0x607D, 2}, DataType::I32};
inline constexpr ObjectDef kMaxProfileVelocity{{0x607F, 0}, DataType::U32};
inline constexpr ObjectDef kProfileVelocity{{0x6081, 0}, DataType::U32};
inline constexpr ObjectDef kProfileAcceleration{{0x6083, 0}, DataType::U32};
inline constexpr ObjectDef kProfileDeceleration{{0x6084, 0}, DataType::U32};
inline constexpr ObjectDef kQuickStopDeceleration{{0x6085, 0}, DataType::U32};
inline constexpr ObjectDef kTorqueSlope{{0x6087, 0}, DataType::U32};
// Homing [CiA 402 §6.6; AKD digest §9].
inline constexpr ObjectDef kHomingMethod{{0x6098, 0}, DataType::I8};
inline constexpr ObjectDef kHomingSpeedSwitch{{0x6099, 1}, DataType::U32};
inline constexpr ObjectDef kHomingSpeedZero{{0x6099, 2}, DataType::U32};
inline constexpr ObjectDef kHomingAcceleration{{0x609A, 0}, DataType::U32};
// Interpolated position [AKD digest §8].
inline constexpr ObjectDef kIpDataRecord{{0x60C1, 1}, DataType::I32};
inline constexpr ObjectDef kIpTimePeriodUnits{{0x60C2, 1}, DataType::U8};
inline constexpr ObjectDef kIpTimePeriodIndex{{0x60C2, 2}, DataType::I8};
// Cyclic synchronous modes.
inline constexpr ObjectDef kVelocityOffset{{0x60B1, 0}, DataType::I32};
inline constexpr ObjectDef kTorqueOffset{{0x60B2, 0}, DataType::I16};
inline constexpr ObjectDef kDigitalInputs{{0x60FD, 0}, DataType::U32};
inline constexpr ObjectDef kTargetVelocity{{0x60FF, 0}, DataType::I32};
inline constexpr ObjectDef kSupportedDriveModes{{0x6502, 0}, DataType::U32};
}  // namespace obj

// 6060h/6061h values [CiA 402; AKD digest §3.6].
namespace op_mode {
inline constexpr std::int8_t kNone = 0;
inline constexpr std::int8_t kProfilePosition = 1;
inline constexpr std::int8_t kVelocity = 2;
inline constexpr std::int8_t kProfileVelocity = 3;
inline constexpr std::int8_t kProfileTorque = 4;
inline constexpr std::int8_t kHoming = 6;
inline constexpr std::int8_t kInterpolatedPosition = 7;
inline constexpr std::int8_t kCyclicPosition = 8;
inline constexpr std::int8_t kCyclicVelocity = 9;
inline constexpr std::int8_t kCyclicTorque = 10;
}  // namespace op_mode

// 60FDh digital inputs bits [CiA 402].
namespace din {
inline constexpr std::uint32_t kNegativeLimit = 1U << 0;
inline constexpr std::uint32_t kPositiveLimit = 1U << 1;
inline constexpr std::uint32_t kHomeSwitch = 1U << 2;
}  // namespace din

}  // namespace drivegate::cia402
