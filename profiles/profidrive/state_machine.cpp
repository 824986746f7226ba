#include "profiles/profidrive/state_machine.hpp"

#include "profiles/profidrive/control_words.hpp"

namespace drivegate::profidrive {

namespace {
constexpr bool has(std::uint16_t word, std::uint16_t bits) noexcept { return (word & bits) == bits; }
}  // namespace

DriveState decode_state(std::uint16_t zsw1, std::uint16_t last_stw1) noexcept {
  using core::AxisState;
  // Priority as in the standard's diagram [§7]: a fault overrides every state, S1 is entered from
  // everywhere by OFF2/OFF3/fault acknowledge, and bits 4/5 follow STW1 bits 1/2 while in S1
  // (§9.4), so they are read only outside S1.
  if (has(zsw1, zsw1::kFault)) return {AxisState::Fault, false};
  if (has(zsw1, zsw1::kSwitchingOnInhibited)) return {AxisState::SwitchOnDisabled, false};
  const bool on = has(zsw1, zsw1::kReadyToSwitchOn);
  const bool ready = has(zsw1, zsw1::kReadyToOperate);
  const bool enabled = has(zsw1, zsw1::kOperationEnabled);
  if (!on && !ready && !enabled) return {AxisState::NotReadyToSwitchOn, false};
  // OFF2 and OFF3 are reported by the drive itself (bits 4 and 5 low): a coast stop goes to S1 at
  // once, a quick stop (S5 after OFF3) ends in S1 at standstill [§7].
  if (!has(zsw1, zsw1::kNoCoastStop)) return {AxisState::SwitchOnDisabled, true};
  if (!has(zsw1, zsw1::kNoQuickStop)) return {AxisState::QuickStopActive, true};
  if (on && ready) {
    // S4 pattern with OFF3 sent (0x0402: bits 0 and 2 low), the drive not yet showing bit 5 low:
    // the quick stop is under way, not an OFF1 ramp.
    if (enabled && !has(last_stw1, stw1::kNoQuickStop)) return {AxisState::QuickStopActive, true};
    // S3/S4 pattern with OFF1 sent: S5 ramping down to S2 (or S3 -> S2 under way).
    if (!has(last_stw1, stw1::kOn)) return {AxisState::ReadyToSwitchOn, true};
    return {enabled ? AxisState::OperationEnabled : AxisState::SwitchedOn, false};
  }
  if (on && !enabled) return {AxisState::ReadyToSwitchOn, false};
  return {AxisState::Unknown, false};
}

Zsw1Flags decode_flags(std::uint16_t zsw1) noexcept {
  Zsw1Flags f;
  f.warning = has(zsw1, zsw1::kWarning);
  f.control_requested = has(zsw1, zsw1::kControlRequested);
  f.bit8_in_tolerance = has(zsw1, zsw1::kSpeedErrorInTolerance);
  f.bit10_reached = has(zsw1, zsw1::kSpeedReached);
  f.homed = has(zsw1, zsw1::kHomed);
  f.task_acknowledge = has(zsw1, zsw1::kTaskAcknowledge);
  f.drive_stopped = has(zsw1, zsw1::kDriveStopped);
  f.motion_task_active = has(zsw1, zsw1::kMotionTaskActive);
  return f;
}

EnableStep enable_step(DriveState current, std::uint16_t last_stw1, std::uint16_t mode_bits) noexcept {
  using core::AxisState;
  const auto with_mode = [mode_bits](std::uint16_t w) { return static_cast<std::uint16_t>(w | mode_bits); };
  switch (current.state) {
    case AxisState::Fault:
    case AxisState::FaultReactionActive:
      // The edge needs a cycle with bit 7 low first when the last word still had it set.
      if (has(last_stw1, stw1::kFaultAcknowledge)) return {stw1_word::kShutdown, false};
      return {stw1_word::kFaultAcknowledge, false};
    case AxisState::QuickStopActive:
      return {stw1_word::kQuickStop, false};
    default:
      break;
  }
  if (current.stopping) return {last_stw1, false};
  switch (current.state) {
    case AxisState::ReadyToSwitchOn: return {with_mode(stw1_word::kSwitchOn), false};
    case AxisState::SwitchedOn: return {with_mode(stw1_word::kEnableOperation), false};
    case AxisState::OperationEnabled: return {with_mode(stw1_word::kEnableOperation), true};
    default: return {with_mode(stw1_word::kShutdown), false};
  }
}

}  // namespace drivegate::profidrive
