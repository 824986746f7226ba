#include "profiles/cia402/standard_types.hpp"

#include <array>

namespace drivegate::cia402 {
namespace {

using core::ParamType;

// CiA 301 §7.5.2: communication profile objects. `sub0` is the type of sub-index 0 (a count for
// arrays and records), `subs` the type of the others.
struct CommObject {
  std::uint16_t first;
  std::uint16_t last;
  ParamType sub0;
  ParamType subs;
};

constexpr std::array<CommObject, 27> kComm{{
    {0x1000, 0x1000, ParamType::U32, ParamType::Unknown},            // device type
    {0x1001, 0x1001, ParamType::U8, ParamType::Unknown},             // error register
    {0x1002, 0x1002, ParamType::U32, ParamType::Unknown},            // manufacturer status register
    {0x1003, 0x1003, ParamType::U8, ParamType::U32},                 // pre-defined error field
    {0x1005, 0x1007, ParamType::U32, ParamType::Unknown},            // COB-ID SYNC, cycle, window
    {0x1008, 0x100A, ParamType::VisibleString, ParamType::Unknown},  // device name, hw, sw version
    {0x100C, 0x100C, ParamType::U16, ParamType::Unknown},            // guard time
    {0x100D, 0x100D, ParamType::U8, ParamType::Unknown},             // life time factor
    {0x1010, 0x1011, ParamType::U8, ParamType::U32},                 // store / restore (signatures)
    {0x1012, 0x1012, ParamType::U32, ParamType::Unknown},            // COB-ID TIME
    {0x1013, 0x1013, ParamType::U32, ParamType::Unknown},            // high resolution time stamp
    {0x1014, 0x1014, ParamType::U32, ParamType::Unknown},            // COB-ID EMCY
    {0x1015, 0x1015, ParamType::U16, ParamType::Unknown},            // inhibit time EMCY
    {0x1016, 0x1016, ParamType::U8, ParamType::U32},                 // consumer heartbeat time
    {0x1017, 0x1017, ParamType::U16, ParamType::Unknown},            // producer heartbeat time
    {0x1018, 0x1018, ParamType::U8, ParamType::U32},                 // identity
    {0x1019, 0x1019, ParamType::U8, ParamType::Unknown},             // synchronous counter overflow
    {0x1020, 0x1020, ParamType::U8, ParamType::U32},                 // verify configuration
    {0x1029, 0x1029, ParamType::U8, ParamType::U8},                  // error behaviour
    {0x1200, 0x127F, ParamType::U8, ParamType::Unknown},             // SDO server (subs below)
    {0x1280, 0x12FF, ParamType::U8, ParamType::Unknown},             // SDO client (subs below)
    {0x1400, 0x15FF, ParamType::U8, ParamType::Unknown},             // RPDO communication (below)
    {0x1600, 0x17FF, ParamType::U8, ParamType::U32},                 // RPDO mapping
    {0x1800, 0x19FF, ParamType::U8, ParamType::Unknown},             // TPDO communication (below)
    {0x1A00, 0x1BFF, ParamType::U8, ParamType::U32},                 // TPDO mapping
    {0x1F51, 0x1F51, ParamType::U8, ParamType::U8},                  // program control
    {0x1F80, 0x1F80, ParamType::U32, ParamType::Unknown},            // NMT start-up
}};

ParamType comm_type(ObjectId id) noexcept {
  for (const auto& c : kComm) {
    if (id.index < c.first || id.index > c.last) continue;
    if (id.sub == 0) return c.sub0;
    if (c.subs != ParamType::Unknown) return c.subs;
    if (id.index >= 0x1200 && id.index <= 0x12FF) {  // COB-ID client->server, server->client, node-ID
      return id.sub <= 2 ? ParamType::U32 : id.sub == 3 ? ParamType::U8 : ParamType::Unknown;
    }
    if ((id.index >= 0x1400 && id.index <= 0x15FF) || (id.index >= 0x1800 && id.index <= 0x19FF)) {
      switch (id.sub) {  // COB-ID, transmission type, inhibit time, (reserved), event timer, SYNC start
        case 1: return ParamType::U32;
        case 2: return ParamType::U8;
        case 3: return ParamType::U16;
        case 5: return ParamType::U16;
        case 6: return ParamType::U8;
        default: return ParamType::Unknown;
      }
    }
    return ParamType::Unknown;
  }
  return ParamType::Unknown;
}

constexpr std::array kProfileObjects{
    obj::kErrorRegister, obj::kErrorCode, obj::kControlword, obj::kStatusword, obj::kVlTargetVelocity,
    obj::kVlVelocityDemand, obj::kVlVelocityActual, obj::kVlAccelerationDeltaSpeed, obj::kVlAccelerationDeltaTime,
    obj::kVlDecelerationDeltaSpeed, obj::kVlDecelerationDeltaTime, obj::kQuickStopOption, obj::kShutdownOption,
    obj::kDisableOperationOption, obj::kHaltOption, obj::kFaultReactionOption, obj::kModesOfOperation,
    obj::kModesOfOperationDisplay, obj::kPositionDemand, obj::kPositionActual, obj::kFollowingErrorWindow,
    obj::kFollowingErrorTimeout, obj::kPositionWindow, obj::kPositionWindowTime, obj::kVelocityActual,
    obj::kVelocityWindow, obj::kVelocityWindowTime, obj::kTargetTorque, obj::kMaxTorque, obj::kTorqueActual,
    obj::kTargetPosition, obj::kHomeOffset, obj::kSoftwareLimitMin, obj::kSoftwareLimitMax,
    obj::kMaxProfileVelocity, obj::kProfileVelocity, obj::kProfileAcceleration, obj::kProfileDeceleration,
    obj::kQuickStopDeceleration, obj::kTorqueSlope, obj::kHomingMethod, obj::kHomingSpeedSwitch,
    obj::kHomingSpeedZero, obj::kHomingAcceleration, obj::kIpDataRecord, obj::kIpTimePeriodUnits,
    obj::kIpTimePeriodIndex, obj::kVelocityOffset, obj::kTorqueOffset, obj::kDigitalInputs, obj::kTargetVelocity,
    obj::kSupportedDriveModes,
    // Read often, not used by the profile [CiA 402 §6].
    ObjectDef{{0x6063, 0}, DataType::I32},  // position actual value (increments)
    ObjectDef{{0x6078, 0}, DataType::I16},  // current actual value
    ObjectDef{{0x6079, 0}, DataType::U32},  // DC link circuit voltage
    ObjectDef{{0x607E, 0}, DataType::U8},   // polarity
    ObjectDef{{0x60F4, 0}, DataType::I32},  // following error actual value
};

}  // namespace

ParamType to_param_type(DataType t) noexcept {
  switch (t) {
    case DataType::I8: return ParamType::I8;
    case DataType::U8: return ParamType::U8;
    case DataType::I16: return ParamType::I16;
    case DataType::U16: return ParamType::U16;
    case DataType::I32: return ParamType::I32;
    case DataType::U32: return ParamType::U32;
  }
  return ParamType::Unknown;
}

std::optional<DataType> profile_object_type(ObjectId id) noexcept {
  for (const auto& d : kProfileObjects)
    if (d.id == id) return d.type;
  return std::nullopt;
}

ParamType standard_param_type(ObjectId id) noexcept {
  if (id.index < 0x2000) return comm_type(id);
  const auto t = profile_object_type(id);
  return t ? to_param_type(*t) : ParamType::Unknown;
}

}  // namespace drivegate::cia402
