#pragma once
// The unified axis model (DESIGN.md §4): states, link states, modes, command kinds, reply
// statuses and event kinds, with their names. Every bus and profile maps onto these.
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace drivegate::core {

enum class AxisState : std::uint8_t {
  NotReadyToSwitchOn,
  SwitchOnDisabled,
  ReadyToSwitchOn,
  SwitchedOn,
  OperationEnabled,
  QuickStopActive,
  FaultReactionActive,
  Fault,
  Unknown,  // no valid status from the drive yet (link not up)
};

// Degraded: the drive answers but stopped following the gateway (its controlword or telegram);
// the gateway is stopping it over the acyclic channel and will reconfigure it.
enum class LinkState : std::uint8_t { Offline, Booting, Configuring, Ready, Operational, Lost, Degraded };

enum class Mode : std::uint8_t {
  None,  // no mode selected yet
  ProfilePosition,
  ProfileVelocity,
  Velocity,  // CiA 402 vl
  ProfileTorque,
  Homing,
  InterpolatedPosition,
  CyclicPosition,
  CyclicVelocity,
  CyclicTorque,
  TraversingBlock,  // PROFIdrive program mode
};
inline constexpr std::size_t kModeCount = 11;

enum class CommandKind : std::uint8_t {
  Enable,
  Disable,
  QuickStop,
  Halt,
  Resume,
  FaultReset,
  SetMode,
  Move,      // profile position: absolute or relative
  Velocity,  // profile velocity / vl jog
  Torque,    // profile torque
  Home,
  RunBlock,  // PROFIdrive traversing block
  Stop,      // bring the axis to standstill in its mode and keep it enabled (halt + clear set-points)
};
inline constexpr std::size_t kCommandKindCount = 13;

enum class ReplyStatus : std::uint8_t { Accepted, Rejected, Completed, Failed };

enum class EventKind : std::uint8_t {
  StateChanged,
  LinkChanged,
  ModeChanged,
  Fault,         // drive fault with code and text
  FaultCleared,
  Warning,
  CommandTimeout,  // set-point source went silent; the axis was stopped
  Info,
  ControlLost,  // the drive stopped following the gateway's controlword/telegram; it is being stopped
  DuplicateGateway,  // another instance of this gateway (same name) is on the DDS domain
  Emcy,  // a message the drive sent on its own (CANopen EMCY): code, error register, vendor bytes
};

// Modes that need a live command source: silence longer than the axis' command timeout stops them.
constexpr bool mode_needs_live_source(Mode m) noexcept {
  switch (m) {
    case Mode::ProfileVelocity:
    case Mode::Velocity:
    case Mode::ProfileTorque:
    case Mode::InterpolatedPosition:
    case Mode::CyclicPosition:
    case Mode::CyclicVelocity:
    case Mode::CyclicTorque:
      return true;
    default:
      return false;
  }
}
constexpr bool mode_is_cyclic(Mode m) noexcept {
  return m == Mode::InterpolatedPosition || m == Mode::CyclicPosition || m == Mode::CyclicVelocity ||
         m == Mode::CyclicTorque;
}

// Names as they appear in YAML, on DDS and in the CLI. The views refer to string literals, so
// .data() is null-terminated and usable with printf-style formatting without a copy.
std::string_view to_string(AxisState s) noexcept;
std::string_view to_string(LinkState s) noexcept;
std::string_view to_string(Mode m) noexcept;
std::string_view to_string(CommandKind k) noexcept;
std::string_view to_string(ReplyStatus s) noexcept;
std::string_view to_string(EventKind k) noexcept;

// Mode names accept the long form ("profile_position") and the CiA 402 short form ("pp").
std::optional<Mode> parse_mode(std::string_view name) noexcept;
std::optional<CommandKind> parse_command_kind(std::string_view name) noexcept;
// "pp, pv, vl, tq, hm, ip, csp, csv, cst, tb" for error messages.
std::string_view mode_short_name(Mode m) noexcept;

// A set of modes as a bit mask (device capabilities, config).
class ModeSet {
 public:
  constexpr ModeSet() noexcept = default;
  constexpr void add(Mode m) noexcept { bits_ |= bit(m); }
  [[nodiscard]] constexpr bool contains(Mode m) const noexcept { return (bits_ & bit(m)) != 0; }
  [[nodiscard]] constexpr bool empty() const noexcept { return bits_ == 0; }
  [[nodiscard]] constexpr std::uint32_t bits() const noexcept { return bits_; }

 private:
  static constexpr std::uint32_t bit(Mode m) noexcept { return 1U << static_cast<unsigned>(m); }
  std::uint32_t bits_ = 0;
};

}  // namespace drivegate::core
