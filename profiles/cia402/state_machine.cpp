#include "profiles/cia402/state_machine.hpp"

#include "profiles/cia402/controlword.hpp"
#include "profiles/cia402/master_helpers.hpp"

namespace drivegate::cia402 {

using core::AxisState;

namespace {

// Position along the enable walk; a drop to a lower rank during the walk was not commanded.
int enable_rank(AxisState s) noexcept {
  switch (s) {
    case AxisState::SwitchOnDisabled: return 1;
    case AxisState::ReadyToSwitchOn: return 2;
    case AxisState::SwitchedOn: return 3;
    case AxisState::OperationEnabled: return 4;
    default: return 0;
  }
}

}  // namespace

void DeviceControl::start(DeviceGoal goal, AxisState state, core::TimePoint now) noexcept {
  goal_ = goal;
  step_state_ = state;
  step_since_ = now;
  reset_edge_sent_ = false;
  failure_.clear();
}

void DeviceControl::hold(std::uint16_t controlword) noexcept {
  goal_ = DeviceGoal::Hold;
  cw_ = controlword;
  reset_edge_sent_ = false;
}

void DeviceControl::note_progress(AxisState state, core::TimePoint now) noexcept {
  if (state != step_state_) {
    step_state_ = state;
    step_since_ = now;
  }
}

DeviceProgress DeviceControl::finish(std::uint16_t hold_cw) noexcept {
  hold(hold_cw);
  return DeviceProgress::Done;
}

DeviceProgress DeviceControl::fail_timeout(AxisState state) noexcept {
  failure_.format("drive stayed in %s for %lld ms after controlword 0x%04X (check hardware enable, DC bus and fault state)",
                  core::to_string(state).data(), ms(step_timeout_), static_cast<unsigned>(cw_));
  return DeviceProgress::Failed;
}

DeviceProgress DeviceControl::step(AxisState state, core::TimePoint now) noexcept {
  switch (goal_) {
    case DeviceGoal::Hold: return DeviceProgress::Idle;
    case DeviceGoal::Enable: return step_enable(state, now);
    case DeviceGoal::FaultReset: return step_fault_reset(state, now);
    case DeviceGoal::Disable:
      cw_ = cw::kDisableVoltage;
      // Not ready to switch on and Fault have the power stage off as well [AKD digest §3.2].
      if (state == AxisState::SwitchOnDisabled || state == AxisState::NotReadyToSwitchOn || in_fault(state)) {
        return finish(cw::kDisableVoltage);
      }
      break;
    case DeviceGoal::QuickStop:
      if (state == AxisState::QuickStopActive || state == AxisState::SwitchOnDisabled ||
          state == AxisState::NotReadyToSwitchOn || in_fault(state)) {
        // Keep bit 2 low so that the drive does not take transition 16 back to Operation enabled.
        return finish(cw::kQuickStop);
      }
      cw_ = cw::kQuickStop;
      break;
  }
  note_progress(state, now);
  if (now - step_since_ > step_timeout_) {
    const auto result = fail_timeout(state);
    hold(cw::kDisableVoltage);
    return result;
  }
  return DeviceProgress::Running;
}

DeviceProgress DeviceControl::step_enable(AxisState state, core::TimePoint now) noexcept {
  if (in_fault(state)) {
    failure_.format("drive went to %s during enable", core::to_string(state).data());
    hold(cw::kDisableVoltage);
    return DeviceProgress::Failed;
  }
  if (enable_rank(state) != 0 && enable_rank(state) < enable_rank(step_state_)) {
    failure_.format("drive fell back from %s to %s during enable (hardware enable or DC bus lost?)",
                    core::to_string(step_state_).data(), core::to_string(state).data());
    hold(cw::kDisableVoltage);
    return DeviceProgress::Failed;
  }
  // One command per observed state: each is the one legal transition out of that state
  // [AKD digest §14 item 7: 0x0006 -> 0x21, 0x0007 -> 0x23, 0x000F -> 0x27].
  switch (state) {
    case AxisState::OperationEnabled: return finish(cw::kEnableOperation);
    case AxisState::SwitchOnDisabled: cw_ = cw::kShutdown; break;
    case AxisState::ReadyToSwitchOn: cw_ = cw::kSwitchOn; break;
    case AxisState::SwitchedOn: cw_ = cw::kEnableOperation; break;
    // Transition 16 is not offered by every drive (NORD digest §3.2), so leave Quick stop active
    // through Switch on disabled (transition 12) and walk up from there.
    case AxisState::QuickStopActive: cw_ = cw::kDisableVoltage; break;
    default: cw_ = cw::kDisableVoltage; break;  // not ready yet: transition 1 is the drive's own
  }
  note_progress(state, now);
  if (now - step_since_ > step_timeout_) {
    const auto result = fail_timeout(state);
    hold(cw::kDisableVoltage);
    return result;
  }
  return DeviceProgress::Running;
}

DeviceProgress DeviceControl::step_fault_reset(AxisState state, core::TimePoint now) noexcept {
  if (!in_fault(state)) {
    // Left Fault (or never was in it): clear bit 7 again [AKD digest §3.2 #15].
    return finish(cw::kDisableVoltage);
  }
  if (state == AxisState::FaultReactionActive) {
    cw_ = cw::kDisableVoltage;  // wait for the reaction to end; the edge only counts in Fault
  } else if (!reset_edge_sent_) {
    if ((cw_ & cw::kFaultReset) != 0) {
      cw_ = cw::kDisableVoltage;  // bit 7 was high: send it low first so that the next 1 is an edge
    } else {
      cw_ = cw::kDisableVoltage | cw::kFaultReset;  // 0x0080
      reset_edge_sent_ = true;
      step_since_ = now;
    }
  }
  if (reset_edge_sent_ && now - step_since_ > step_timeout_) {
    failure_.format("drive still in fault %lld ms after fault reset (cause still present?)", ms(step_timeout_));
    hold(cw::kDisableVoltage);
    return DeviceProgress::Failed;
  }
  if (!reset_edge_sent_ && now - step_since_ > step_timeout_) {
    const auto result = fail_timeout(state);
    hold(cw::kDisableVoltage);
    return result;
  }
  return DeviceProgress::Running;
}

}  // namespace drivegate::cia402
