#include "core/axis_types.hpp"

namespace drivegate::core {

std::string_view to_string(AxisState s) noexcept {
  switch (s) {
    case AxisState::NotReadyToSwitchOn: return "not_ready_to_switch_on";
    case AxisState::SwitchOnDisabled: return "switch_on_disabled";
    case AxisState::ReadyToSwitchOn: return "ready_to_switch_on";
    case AxisState::SwitchedOn: return "switched_on";
    case AxisState::OperationEnabled: return "operation_enabled";
    case AxisState::QuickStopActive: return "quick_stop_active";
    case AxisState::FaultReactionActive: return "fault_reaction_active";
    case AxisState::Fault: return "fault";
    case AxisState::Unknown: return "unknown";
  }
  return "unknown";
}

std::string_view to_string(LinkState s) noexcept {
  switch (s) {
    case LinkState::Offline: return "offline";
    case LinkState::Booting: return "booting";
    case LinkState::Configuring: return "configuring";
    case LinkState::Ready: return "ready";
    case LinkState::Operational: return "operational";
    case LinkState::Lost: return "lost";
    case LinkState::Degraded: return "degraded";
  }
  return "offline";
}

namespace {
struct ModeName {
  Mode mode;
  std::string_view long_name;
  std::string_view short_name;
};
constexpr std::array<ModeName, kModeCount> kModeNames{{
    {Mode::None, "none", "none"},
    {Mode::ProfilePosition, "profile_position", "pp"},
    {Mode::ProfileVelocity, "profile_velocity", "pv"},
    {Mode::Velocity, "velocity", "vl"},
    {Mode::ProfileTorque, "profile_torque", "tq"},
    {Mode::Homing, "homing", "hm"},
    {Mode::InterpolatedPosition, "interpolated_position", "ip"},
    {Mode::CyclicPosition, "cyclic_position", "csp"},
    {Mode::CyclicVelocity, "cyclic_velocity", "csv"},
    {Mode::CyclicTorque, "cyclic_torque", "cst"},
    {Mode::TraversingBlock, "traversing_block", "tb"},
}};

constexpr std::array<std::string_view, kCommandKindCount> kCommandNames{
    "enable", "disable", "quick_stop", "halt", "resume", "fault_reset", "set_mode",
    "move",   "velocity", "torque",    "home", "run_block", "stop"};
}  // namespace

std::string_view to_string(Mode m) noexcept {
  for (const auto& n : kModeNames)
    if (n.mode == m) return n.long_name;
  return "none";
}

std::string_view mode_short_name(Mode m) noexcept {
  for (const auto& n : kModeNames)
    if (n.mode == m) return n.short_name;
  return "none";
}

std::optional<Mode> parse_mode(std::string_view name) noexcept {
  for (const auto& n : kModeNames)
    if (n.long_name == name || n.short_name == name) return n.mode;
  return std::nullopt;
}

std::string_view to_string(CommandKind k) noexcept {
  const auto i = static_cast<std::size_t>(k);
  return i < kCommandNames.size() ? kCommandNames[i] : "unknown";
}

std::optional<CommandKind> parse_command_kind(std::string_view name) noexcept {
  for (std::size_t i = 0; i < kCommandNames.size(); ++i)
    if (kCommandNames[i] == name) return static_cast<CommandKind>(i);
  return std::nullopt;
}

std::string_view to_string(ReplyStatus s) noexcept {
  switch (s) {
    case ReplyStatus::Accepted: return "accepted";
    case ReplyStatus::Rejected: return "rejected";
    case ReplyStatus::Completed: return "completed";
    case ReplyStatus::Failed: return "failed";
  }
  return "failed";
}

std::string_view to_string(EventKind k) noexcept {
  switch (k) {
    case EventKind::StateChanged: return "state_changed";
    case EventKind::LinkChanged: return "link_changed";
    case EventKind::ModeChanged: return "mode_changed";
    case EventKind::Fault: return "fault";
    case EventKind::FaultCleared: return "fault_cleared";
    case EventKind::Warning: return "warning";
    case EventKind::CommandTimeout: return "command_timeout";
    case EventKind::Info: return "info";
    case EventKind::ControlLost: return "control_lost";
    case EventKind::DuplicateGateway: return "duplicate_gateway";
    case EventKind::Emcy: return "emcy";
  }
  return "info";
}

}  // namespace drivegate::core
