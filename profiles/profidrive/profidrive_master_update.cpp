// ProfidriveMaster: the cycle. Inputs and their freshness, state tracking and events, device
// control (the general state machine), outputs, feedback.
#include "profiles/profidrive/master_helpers.hpp"
#include "profiles/profidrive/profidrive_master.hpp"
#include "profiles/profidrive/scaling.hpp"

namespace drivegate::profidrive {

using core::AxisState;
using core::EventKind;
using core::Mode;

namespace {

// The PROFIdrive name of a state, for failure texts a person compares with the drive's display.
const char* state_name(DriveState s) noexcept {
  switch (s.state) {
    case AxisState::SwitchOnDisabled: return s.stopping ? "S1 switching on inhibited (coasting)" : "S1 switching on inhibited";
    case AxisState::ReadyToSwitchOn: return s.stopping ? "S5 switching off (OFF1 ramp)" : "S2 ready for switching on";
    case AxisState::SwitchedOn: return "S3 switched on";
    case AxisState::OperationEnabled: return "S4 operation";
    case AxisState::QuickStopActive: return "S5 switching off (OFF3 quick stop)";
    case AxisState::Fault:
    case AxisState::FaultReactionActive: return "fault";
    case AxisState::NotReadyToSwitchOn: return "not ready (ZSW1 bits 0..2 and 6 low)";
    default: return "an undefined ZSW1 pattern";
  }
}

// The transition an enable walk waits for in state `s` [§7, §24 step 9].
const char* enable_step_name(DriveState s) noexcept {
  if (s.stopping) return "the drive to finish stopping";
  switch (s.state) {
    case AxisState::ReadyToSwitchOn: return "S2 -> S3 (switch on, STW1 bit 0)";
    case AxisState::SwitchedOn: return "S3 -> S4 (enable operation, STW1 bit 3)";
    default: return "S1 -> S2 (ready, STW1 bits 1 and 2 with bit 0 low)";
  }
}

}  // namespace

void ProfidriveMaster::update(core::TimePoint now, core::ControllerSink& sink) noexcept {
  ++cycle_;
  if (read_inputs(now, sink)) {
    track_state(sink);
    supervise_control(now, sink);
    run_device(now, sink);
    run_motion(now, sink);
    if (halt_slot_.active && telegrams_ >= halt_settle_until_ && at_standstill()) halt_slot_.complete(sink);
    if (mode_ != fb_.mode) {
      core::Text t;
      t.format("mode %s -> %s", core::to_string(fb_.mode).data(), core::to_string(mode_).data());
      sink.event(EventKind::ModeChanged, static_cast<std::uint32_t>(mode_), t.view());
    }
  }
  write_outputs();
  run_channel(now, sink);
  fill_feedback();
}

bool ProfidriveMaster::read_inputs(core::TimePoint now, core::ControllerSink& sink) noexcept {
  const std::span<const std::uint8_t> image = port_.actual();
  if (!image.empty() && port_.actual_fresh()) {
    Actuals a = actual_;
    if (decode_actuals(layout_, image, a) == TelegramError::None) {
      actual_ = a;
      fresh_at_ = now;
      if (layout_.carries(Signal::NistA)) velocity_ = native_from_nist(actual_.nist_a);
      else if (caps_.position_actual) velocity_ = derived_velocity_.add(actual_.xist_a, now);
      ++telegrams_;
      if (!actual_valid_) step_since_ = now;
      actual_valid_ = true;
      return true;
    }
    ++bad_telegrams_;  // a wrong length counts as no telegram at all
  }
  if (!actual_valid_) return false;
  const bool invalid = image.empty();
  // The last telegram still holds; handshakes wait for the next one (they count telegrams).
  if (!invalid && now - fresh_at_ <= settings_.stale_timeout) return true;
  core::Text why;
  if (invalid)
    why.assign("actual telegram invalid (no data exchange, or the drive's provider stopped): axis lost, disabled");
  else
    why.format("actual telegram not refreshed for %lld ms: axis lost, disabled", ms(now - fresh_at_));
  sink.event(EventKind::Info, 0, why.view());
  drop_drive(why.view(), sink);
  return false;
}

void ProfidriveMaster::track_state(core::ControllerSink& sink) noexcept {
  const DriveState s = decode_state(actual_.zsw1, stw1_);
  const bool warning = (actual_.zsw1 & zsw1::kWarning) != 0;
  if (warning != warning_) {
    sink.event(EventKind::Warning, warning ? 1U : 0U,
               warning ? "drive reports a warning (ZSW1 bit 7)" : "drive warning cleared");
    warning_ = warning;
  }
  // Bit 9 low: the drive is not taking the controller's commands (local control) [§9.1].
  const bool requested = (actual_.zsw1 & zsw1::kControlRequested) != 0;
  if (requested != control_requested_) {
    sink.event(EventKind::Info, requested ? 1U : 0U,
               requested ? "drive takes the controller's commands again (ZSW1 bit 9 control requested)"
                         : "drive does not take the controller's commands (ZSW1 bit 9 control requested = 0)");
    control_requested_ = requested;
  }
  if (s == state_) return;
  const DriveState prev = state_;
  state_ = s;
  if (s.state != prev.state) {
    core::Text t;
    t.format("%s -> %s", core::to_string(prev.state).data(), core::to_string(s.state).data());
    sink.event(EventKind::StateChanged, static_cast<std::uint32_t>(s.state), t.view());
  }
  if (in_fault(s.state) && !in_fault(prev.state)) {
    const std::string_view reason = "drive fault (ZSW1 bit 3): reading its fault buffer";
    motion_.slot.fail(reason, sink);
    halt_slot_.fail(reason, sink);
    if (device_slot_.active && (goal_ == DeviceGoal::Disable || goal_ == DeviceGoal::QuickStop)) {
      device_slot_.complete(sink);  // the power stage is off: nothing more to switch off
    } else if (goal_ != DeviceGoal::FaultReset) {
      device_slot_.fail(reason, sink);
    }
    if (goal_ != DeviceGoal::FaultReset) safe_outputs();
    // A new fault situation: read PNU 944 -> 947 -> 944 [§18.2, §24 step 12].
    cancel_fault_read();
    fault_reader_ = FaultBufferReader{};
    fault_read_wanted_ = true;
  } else if (in_fault(prev.state) && !in_fault(s.state) && prev.state != AxisState::Unknown) {
    cancel_fault_read();
    fb_.fault_code = 0;
    fb_.fault_text.clear();
    sink.event(EventKind::FaultCleared, 0, "fault cleared");
  } else if (prev.state == AxisState::OperationEnabled && !prev.stopping && !device_slot_.active &&
             (s.state != AxisState::OperationEnabled || s.stopping)) {
    // Not commanded: hardware enable or STO, a local stop, another master.
    core::Text reason;
    reason.format("drive left S4 on its own (now %s): hardware enable or STO?", state_name(s));
    motion_.slot.fail(reason.view(), sink);
    halt_slot_.fail(reason.view(), sink);
    safe_outputs();
  }
}

void ProfidriveMaster::run_device(core::TimePoint now, core::ControllerSink& sink) noexcept {
  if (state_ != step_state_) {
    step_state_ = state_;
    step_since_ = now;
  }
  const std::uint16_t speed_bits = caps_.speed ? stw1::kSpeedRunBits : std::uint16_t{0};
  bool done = false;
  const char* step = nullptr;
  switch (goal_) {
    case DeviceGoal::Hold:
      device_stw1_ = hold_stw1_;
      return;
    case DeviceGoal::Enable: {
      // One legal step a cycle, S1 -> S2 -> S3 -> S4, the speed mode bits with it (§15.1: 0x0476,
      // 0x0477, 0x047F).
      const EnableStep e = enable_step(state_, stw1_, speed_bits);
      device_stw1_ = e.stw1;
      done = e.done;
      step = enable_step_name(state_);
      if (done) hold_stw1_ = stw1_word::kEnableOperation;  // the mode bits come with task_bits()
      break;
    }
    case DeviceGoal::Disable:
      // Disabled means S1 on every bus (CiA 402: switch on disabled), so a client sees one state
      // for "off". OFF1 first: S4 ramps down through S5 to S2, S3 goes to S2 [§7]; then, with the
      // power stage off, bit 2 low takes S2 to S1 and bit 0 low keeps it there [§7: S2 -> S1].
      // Never OFF3 while the OFF1 ramp runs: that would turn a ramp stop into a quick stop. A quick
      // or coast stop already under way goes on to S1 under the same word.
      if (state_.state == AxisState::OperationEnabled || state_.state == AxisState::SwitchedOn ||
          (state_.state == AxisState::ReadyToSwitchOn && state_.stopping)) {
        device_stw1_ = stw1_word::kShutdown;
        step = "OFF1 to S2 (STW1 bit 0 low)";
      } else {
        device_stw1_ = stw1_word::kQuickStop;
        step = "S2 to S1 (STW1 bit 2 low)";
      }
      done = !state_.stopping && (state_.state == AxisState::SwitchOnDisabled ||
                                  state_.state == AxisState::NotReadyToSwitchOn);
      hold_stw1_ = stw1_word::kQuickStop;
      break;
    case DeviceGoal::QuickStop:
      // OFF3: quick stop from S4, then S1; bit 0 low so S1 is where it stays [§7].
      device_stw1_ = stw1_word::kQuickStop;
      done = !state_.stopping && (state_.state == AxisState::SwitchOnDisabled ||
                                  state_.state == AxisState::NotReadyToSwitchOn);
      step = "OFF3 to S1 (STW1 bit 2 low)";
      hold_stw1_ = stw1_word::kQuickStop;
      break;
    case DeviceGoal::FaultReset:
      // A 0->1 edge on bit 7 with bits 0..3 low; the AKD lands in S1 [§8.1, §18.2, §25.17].
      device_stw1_ = fault_reset_stw1(telegrams_ >= acknowledge_from_);
      done = !in_fault(state_.state) && state_.state != AxisState::Unknown;
      step = "fault acknowledge (STW1 bit 7 edge) to S1";
      hold_stw1_ = stw1_word::kQuickStop;
      break;
  }
  if (done) {
    goal_ = DeviceGoal::Hold;
    device_stw1_ = hold_stw1_;
    device_slot_.complete(sink);
    return;
  }
  const core::Duration limit = state_.stopping ? settings_.stop_timeout : settings_.step_timeout;
  if (now - step_since_ <= limit) return;
  failure_.format("%s: drive stayed in %s for %lld ms under STW1 0x%04X, waiting for %s (ZSW1 0x%04X)",
                  core::to_string(device_slot_.kind).data(), state_name(state_), ms(now - step_since_),
                  static_cast<unsigned>(device_stw1_), step, static_cast<unsigned>(actual_.zsw1));
  device_slot_.fail(failure_.view(), sink);
  if (goal_ == DeviceGoal::Enable) {
    safe_outputs();  // a half-finished walk is taken back, not left where it stopped
  } else {
    goal_ = DeviceGoal::Hold;
  }
  device_stw1_ = hold_stw1_;
}

namespace {

// How much power ZSW1 shows: 2 operation enabled, 1 switched on, 0 below - or stopping as told
// (ZSW1 bit 4 or 5 low: OFF2 or OFF3 under way). And the most the STW1 sent allows once the drive
// obeyed it [§7]: OFF1, OFF2 and OFF3 nothing switched on (OFF1 after its ramp), bit 3 low no
// operation.
int power_shown(std::uint16_t z) noexcept {
  if ((z & (zsw1::kFault | zsw1::kSwitchingOnInhibited)) != 0) return 0;
  if ((z & (zsw1::kNoCoastStop | zsw1::kNoQuickStop)) != (zsw1::kNoCoastStop | zsw1::kNoQuickStop)) return 0;
  if ((z & (zsw1::kReadyToSwitchOn | zsw1::kReadyToOperate)) != (zsw1::kReadyToSwitchOn | zsw1::kReadyToOperate))
    return 0;
  return (z & zsw1::kOperationEnabled) != 0 ? 2 : 1;
}
int power_allowed(std::uint16_t w) noexcept {
  if ((w & (stw1::kOn | stw1::kNoCoastStop | stw1::kNoQuickStop)) != (stw1::kOn | stw1::kNoCoastStop | stw1::kNoQuickStop))
    return 0;
  return (w & stw1::kEnableOperation) != 0 ? 2 : 1;
}

}  // namespace

// A drive that does not follow STW1 (local control, another master, a firmware that ignores bit
// 10) is out of the gateway's control: an event and a safe stop by the bus, not a stale state
// (DESIGN.md §4). Judged on fresh telegrams against the STW1 already sent.
void ProfidriveMaster::supervise_control(core::TimePoint now, core::ControllerSink& sink) noexcept {
  if (control_lost_ || fresh_at_ != now) return;
  if (power_shown(actual_.zsw1) <= power_allowed(stw1_)) {
    follow_pending_ = false;
    return;
  }
  if (!follow_pending_) {
    follow_pending_ = true;
    follow_since_ = now;
    return;
  }
  // OFF1 ramps down before the drive leaves S4 [§7]; the others act at once.
  const bool off1_only = (stw1_ & stw1::kOn) == 0 && (stw1_ & stw1::kNoCoastStop) != 0 && (stw1_ & stw1::kNoQuickStop) != 0;
  const core::Duration limit = off1_only ? settings_.stop_timeout : settings_.follow_timeout;
  if (now - follow_since_ <= limit) return;
  control_lost_ = true;
  core::Text why;
  why.format("drive does not follow STW1: still %s %lld ms after STW1 0x%04X told it to leave (ZSW1 0x%04X)",
             state_name(state_), ms(now - follow_since_), static_cast<unsigned>(stw1_),
             static_cast<unsigned>(actual_.zsw1));
  sink.event(EventKind::ControlLost, 0, why.view());
  port_.control_lost(why.view());
}

void ProfidriveMaster::write_outputs() noexcept {
  std::uint16_t w = device_stw1_;
  if (actual_valid_ && state_.state == AxisState::OperationEnabled && !state_.stopping &&
      (w & stw1::kStateMask) == stw1::kStateMask) {
    w = static_cast<std::uint16_t>(w | task_bits());
  }
  Setpoints sp = out_;
  sp.stw1 = static_cast<std::uint16_t>(w | stw1::kControlByPlc);  // never without bit 10 [§25.18]
  sp.stw2 = 0;  // undocumented on the AKD [§12.1]
  if (encode_setpoints(layout_, sp, port_.setpoint()) != TelegramError::None) ++bad_telegrams_;
  stw1_ = sp.stw1;
}

bool ProfidriveMaster::at_standstill() const noexcept {
  // Speed mode: NIST_A at 0, or "speed reached" with the set-point at 0 (a real drive's NIST_A
  // jitters a count or two around 0). Position mode: ZSW1 bit 13 "drive stopped" [§9.3; §23.7
  // for the MDI section's other wording].
  if (caps_.speed)
    return actual_.nist_a == 0 || ((actual_.zsw1 & zsw1::kSpeedReached) != 0 && (out_.nsoll_a == 0 || halt_));
  return (actual_.zsw1 & zsw1::kDriveStopped) != 0;
}

void ProfidriveMaster::fill_feedback() noexcept {
  fb_.valid = actual_valid_;
  fb_.state = actual_valid_ ? state_.state : AxisState::Unknown;
  fb_.stopping = actual_valid_ && (state_.stopping || (motion_.slot.active && motion_.task == Task::Stop));
  fb_.mode = actual_valid_ ? mode_ : Mode::None;
  fb_.statusword = actual_.zsw1;
  fb_.controlword = stw1_;
  if (caps_.position_actual) fb_.position = actual_.xist_a;
  fb_.velocity = velocity_;
  if (layout_.carries(Signal::ItistGlatt)) fb_.torque = actual_.itist_glatt;
  const Zsw1Flags f = decode_flags(actual_.zsw1);
  fb_.warning = f.warning;
  fb_.target_reached = f.bit10_reached;
  // Bits 11 and 13 mean "homed" and "stopped" only in position mode [§9.3]; bit 8's polarity is
  // disputed (§23.8, and the steady state 0x0237 of §20.3 has it clear), so no following error.
  fb_.homed = caps_.position && f.homed;
  fb_.halted = halt_;
}

}  // namespace drivegate::profidrive
