#pragma once
// Commands, set-points, replies, events and snapshots as they cross the boundary between the
// control plane and a cycle thread. All are trivially copyable with inline text so they travel
// through the lock-free queues and seqlocks without heap allocation.
//
// Two unit worlds meet here (DESIGN.md §4): `Command`, `Setpoint` and `AxisSnapshot` are in user
// units (configured per axis); `DriveCommand`, `DriveSetpoint` and `DriveFeedback` are in the
// drive's native units. AxisRunner (core/axis_runner.hpp) is the one place that converts.
#include <array>
#include <cstdint>
#include <span>
#include <type_traits>

#include "core/axis_types.hpp"
#include "core/fixed_string.hpp"
#include "core/param_value.hpp"

namespace drivegate::core {

using CommandId = std::uint64_t;
using AxisIndex = std::uint16_t;  // index of an axis within its bus
inline constexpr AxisIndex kNoAxis = 0xFFFF;
using Text = FixedString<160>;

// Commands the gateway issues itself (command timeout, shutdown) carry ids with this bit set;
// their outcomes produce no reply.
inline constexpr CommandId kInternalCommandBit = CommandId{1} << 63;
constexpr bool is_internal(CommandId id) noexcept { return (id & kInternalCommandBit) != 0; }

// A command in user units. A rate or acceleration of 0 means "use the axis default from the
// configuration"; NaN and infinity are always rejected.
struct Command {
  CommandId id = 0;
  AxisIndex axis = kNoAxis;
  CommandKind kind = CommandKind::Enable;
  Mode mode = Mode::None;  // SetMode target
  double position = 0;     // Move: target (absolute) or distance (relative)
  double velocity = 0;     // Move: profile velocity; Velocity: target velocity (signed)
  double acceleration = 0;
  double deceleration = 0;
  double torque = 0;  // Torque: target torque (percent of rated, or Nm when rated torque is configured)
  bool relative = false;
  bool immediate = true;  // Move: change set immediately (true) or queue after the current one
  std::int16_t homing_method = 0;  // 0: the axis' configured method
  double home_offset = 0;
  double homing_search_velocity = 0;
  double homing_zero_velocity = 0;
  std::int32_t block = 0;  // RunBlock
};

// A streaming set-point for cyclic modes (user units); the field that matters depends on the mode.
struct Setpoint {
  AxisIndex axis = kNoAxis;
  double position = 0;
  double velocity = 0;
  double torque = 0;
};

// The same command in drive units, after validation and conversion.
struct DriveCommand {
  CommandId id = 0;
  CommandKind kind = CommandKind::Enable;
  Mode mode = Mode::None;  // the mode this command runs in (resolved by the runner)
  std::int32_t target_position = 0;
  std::int32_t target_velocity = 0;
  std::uint32_t profile_velocity = 0;
  std::uint32_t profile_acceleration = 0;
  std::uint32_t profile_deceleration = 0;
  std::int16_t target_torque = 0;
  std::uint32_t torque_slope = 0;
  bool relative = false;
  bool immediate = true;
  std::int8_t homing_method = 0;
  std::int32_t home_offset = 0;
  std::uint32_t homing_search_velocity = 0;
  std::uint32_t homing_zero_velocity = 0;
  std::uint32_t homing_acceleration = 0;
  std::int32_t block = 0;
};

struct DriveSetpoint {
  std::int32_t position = 0;
  std::int32_t velocity = 0;
  std::int16_t torque = 0;
};

// What a profile controller reports about its drive every cycle, in drive units.
struct DriveFeedback {
  bool valid = false;  // false until the first status from the drive arrived
  AxisState state = AxisState::Unknown;
  Mode mode = Mode::None;  // mode the drive reports (CiA 402: 6061h)
  std::int32_t position = 0;
  std::int32_t velocity = 0;
  std::int16_t torque = 0;
  std::uint16_t statusword = 0;
  std::uint16_t controlword = 0;
  std::uint32_t fault_code = 0;  // CiA 402: 603Fh / EMCY error code; 0 = none
  Text fault_text;               // fault in words, empty when none
  bool target_reached = false;
  bool homed = false;
  bool following_error = false;
  bool warning = false;
  bool internal_limit = false;
  bool halted = false;
  bool stopping = false;  // ramping down (quick stop, halt, OFF1)
};

// Why a link is in its state, in the bus' words (Bus::link_detail()).
using LinkDetail = FixedString<200>;

// The axis as clients see it, in user units.
struct AxisSnapshot {
  AxisIndex axis = kNoAxis;
  AxisState state = AxisState::Unknown;
  LinkState link = LinkState::Offline;
  LinkDetail link_detail;        // why the link is in its state ("" when the bus says nothing)
  std::int64_t link_since_ns = 0;  // monotonic time the link entered its state (as stamp_ns)
  Mode mode = Mode::None;
  double position = 0;
  double velocity = 0;
  double torque = 0;
  std::uint32_t fault_code = 0;
  Text fault_text;
  bool target_reached = false;
  bool homed = false;
  bool warning = false;
  bool stopping = false;
  bool following_error = false;
  std::uint16_t statusword = 0;
  CommandId active_command = 0;
  std::int64_t stamp_ns = 0;  // monotonic time of the cycle that produced it
  std::uint64_t cycle = 0;
};

struct Reply {
  CommandId id = 0;
  AxisIndex axis = kNoAxis;
  ReplyStatus status = ReplyStatus::Accepted;
  Text reason;
};

struct Event {
  AxisIndex axis = kNoAxis;  // kNoAxis: the event is about the bus
  EventKind kind = EventKind::Info;
  AxisState state = AxisState::Unknown;
  std::uint32_t code = 0;
  Text text;
  std::int64_t stamp_ns = 0;
};

// A PROFINET record (IODReadReq/IODWriteReq) [IEC 61158-6-10], for a ParamRequest that names
// one instead of an object (core/record_address.hpp reads and writes them as text). The record
// goes to the device of the request's axis, or with `io` set to the bus' I/O device of that index.
inline constexpr std::uint16_t kNoIo = 0xFFFF;
struct RecordAddress {
  bool valid = false;      // false: the request is object access (index/sub)
  bool api_given = false;  // false: the API of the submodule the configuration puts there, else 0
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint16_t subslot = 0;
  std::uint16_t index = 0;
  std::uint16_t io = kNoIo;
};

// Parameter access by object index/sub-index (CiA 402 drives) for the DDS parameter topic: the
// object's bytes as they travel on the bus (little-endian), typed by core/param_value.hpp. The
// daemon resolved the type (request, EDS, device profile) and encoded a write's value already.
// With `record` valid it is a record's access instead: its bytes as the record carries them,
// except that a value of a fixed-size type (integers, reals) is little-endian here like the
// others and the bus turns it into the record's big-endian order [IEC 61158-6-10].
struct ParamRequest {
  CommandId id = 0;
  AxisIndex axis = kNoAxis;
  bool write = false;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  RecordAddress record{};
  ParamType type = ParamType::Unknown;  // Unknown: reads take whatever size the drive sends
  std::uint16_t size = 0;               // write: bytes in data
  std::array<std::uint8_t, kMaxParamBytes> data{};
  [[nodiscard]] std::span<const std::uint8_t> bytes() const noexcept { return {data.data(), size}; }
};

struct ParamReply {
  CommandId id = 0;
  AxisIndex axis = kNoAxis;
  bool ok = false;
  std::uint32_t error_code = 0;  // e.g. CiA 301 SDO abort code; a record's PNIOStatus (code, decode, code 1, code 2)
  Text error;                    // in words
  ParamType type = ParamType::Unknown;
  std::uint16_t size = 0;  // bytes in data: what was read, or what was written
  std::array<std::uint8_t, kMaxParamBytes> data{};
  [[nodiscard]] std::span<const std::uint8_t> bytes() const noexcept { return {data.data(), size}; }
};

static_assert(std::is_trivially_copyable_v<Command>);
static_assert(std::is_trivially_copyable_v<RecordAddress>);
static_assert(std::is_trivially_copyable_v<ParamRequest>);
static_assert(std::is_trivially_copyable_v<ParamReply>);
static_assert(std::is_trivially_copyable_v<AxisSnapshot>);
static_assert(std::is_trivially_copyable_v<Reply>);
static_assert(std::is_trivially_copyable_v<Event>);
static_assert(std::is_trivially_copyable_v<DriveFeedback>);

}  // namespace drivegate::core
