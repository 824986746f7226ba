// Cia402Master: mode selection and the per-mode handshakes [AKD digest §3.6, §5, §6, §8-§10;
// NORD digest §5], halt, and the hold values of the cyclic modes.
#include <cstdlib>

#include "profiles/cia402/cia402_master.hpp"
#include "profiles/cia402/controlword.hpp"
#include "profiles/cia402/master_helpers.hpp"
#include "profiles/cia402/op_modes.hpp"
#include "profiles/cia402/sdo_abort.hpp"
#include "profiles/cia402/statusword.hpp"

namespace drivegate::cia402 {

using core::AxisState;
using core::CommandKind;
using core::Mode;

void Cia402Master::start_motion(const core::DriveCommand& cmd, Mode mode, core::TimePoint now) noexcept {
  abandon_motion_requests();  // of the command this one supersedes
  motion_.slot = Slot{true, cmd.id, cmd.kind};
  motion_.cmd = cmd;
  motion_.mode = mode;
  motion_.since = now;
  // A set-point or homing start needs a fresh 0->1 edge on bit 4; dropping it also ends a homing run
  // or set-point handshake that this command replaces [AKD digest §9.3: 1->0 aborts homing].
  bit4_ = false;
  pp_bits_ = 0;
  const bool need_switch = cmd.kind != CommandKind::Stop &&
                           (cmd.kind == CommandKind::SetMode || !display_known_ || mode != from_op_mode(display_mode_));
  if (need_switch) {
    mode_req_ = ModeRequest{*to_op_mode(mode), kNoRequest, false};
    mode_out_ = mode_req_.value;
    mode_out_valid_ = true;
    mode_switching_ = true;
    mode_since_ = now;
    motion_.phase = Phase::SwitchMode;
    // The drive follows a cyclic target from the SYNC that carries the new mode, before 6061h
    // confirms it and hold_cyclic() takes over: the image must already hold where the axis
    // stands, not a target an earlier mode left there (a pp target from before a homing run that
    // moved the coordinates makes the drive jump into a following error) [AKD digest part 2 §14
    // step 17: csp takes 607Ah at every SYNC].
    if (core::mode_is_cyclic(mode)) write_safe_holds();
  } else {
    mode_switching_ = false;
    enter_stage(now);
  }
}

void Cia402Master::enter_stage(core::TimePoint now) noexcept {
  const core::DriveCommand& c = motion_.cmd;
  motion_.phase = Phase::Stage;
  motion_.since = now;
  batch_.clear(io_);
  // A rate or ramp of 0 keeps what the drive has (the runner already substituted axis defaults).
  const auto add_nonzero = [this](ObjectDef def, std::uint32_t v) {
    if (v != 0) batch_.add(def, v);
  };
  switch (c.kind) {
    case CommandKind::Move:
      batch_.add(obj::kTargetPosition, c.target_position);
      add_nonzero(obj::kProfileVelocity, c.profile_velocity);
      add_nonzero(obj::kProfileAcceleration, c.profile_acceleration);
      add_nonzero(obj::kProfileDeceleration, c.profile_deceleration);
      // Bit 6 is "relative" in CiA 402 and "absolute" on a drive with quirk pp_bit6_absolute.
      pp_bits_ = static_cast<std::uint16_t>((c.immediate ? cw::kChangeImmediately : 0U) |
                                            (c.relative != settings_.pp_bit6_absolute ? cw::kRelative : 0U));
      break;
    case CommandKind::Velocity:
      if (motion_.mode == Mode::Velocity) {
        batch_.add(obj::kVlTargetVelocity, c.target_velocity);
      } else {
        add_nonzero(obj::kProfileAcceleration, c.profile_acceleration);
        add_nonzero(obj::kProfileDeceleration, c.profile_deceleration);
        batch_.add(obj::kTargetVelocity, c.target_velocity);
      }
      break;
    case CommandKind::Torque:
      add_nonzero(obj::kTorqueSlope, c.torque_slope);
      batch_.add(obj::kTargetTorque, c.target_torque);
      break;
    case CommandKind::Home:
      // Not PDO-mappable on the AKD: these go out as acyclic writes [AKD digest §14 item 15].
      if (c.homing_method != 0) batch_.add(obj::kHomingMethod, c.homing_method);
      add_nonzero(obj::kHomingSpeedSwitch, c.homing_search_velocity);
      add_nonzero(obj::kHomingSpeedZero, c.homing_zero_velocity);
      add_nonzero(obj::kHomingAcceleration, c.homing_acceleration);
      batch_.add(obj::kHomeOffset, c.home_offset);
      break;
    case CommandKind::Stop:
      switch (motion_.mode) {
        case Mode::ProfileVelocity: batch_.add(obj::kTargetVelocity, 0); break;
        case Mode::Velocity: batch_.add(obj::kVlTargetVelocity, 0); break;
        case Mode::ProfileTorque: batch_.add(obj::kTargetTorque, 0); break;
        case Mode::ProfilePosition:
        case Mode::Homing: halt_ = true; break;  // halt keeps enable; in hm bit 4 already dropped
        default: restart_cyclic_hold(); break;  // cyclic modes: hold position / zero velocity or torque
      }
      break;
    default: break;
  }
}

void Cia402Master::run_motion(core::TimePoint now, core::ControllerSink& sink) noexcept {
  if (!motion_.slot.active) return;
  if (motion_.phase == Phase::SwitchMode) {
    if (!run_mode_switch(now, sink)) return;
    if (motion_.slot.kind == CommandKind::SetMode) {
      motion_.slot.complete(sink);
      return;
    }
    enter_stage(now);  // set-points again after a mode change [AKD digest §3.6]
  }
  if (motion_.phase == Phase::Stage) {
    const WriteBatch::Status st = batch_.run(io_);
    if (st == WriteBatch::Status::Pending) {
      if (now - motion_.since > settings_.stage_timeout) {
        core::Text reason;
        reason.format("drive did not take %04Xh:%02X = %lld within %lld ms: %s (no answer, or no free request slot)",
                      static_cast<unsigned>(batch_.pending_object().id.index),
                      static_cast<unsigned>(batch_.pending_object().id.sub), static_cast<long long>(batch_.pending_value()),
                      ms(settings_.stage_timeout), sdo_abort_text(0x05040000).data());
        fail_motion(reason.view(), sink);
      }
      return;
    }
    if (st == WriteBatch::Status::Failed) {
      core::Text reason;
      reason.format("drive refused %04Xh:%02X = %lld: %s (abort code 0x%08X)",
                    static_cast<unsigned>(batch_.failed_object().id.index),
                    static_cast<unsigned>(batch_.failed_object().id.sub), static_cast<long long>(batch_.failed_value()),
                    sdo_abort_text(batch_.failed_abort()).data(), static_cast<unsigned>(batch_.failed_abort()));
      fail_motion(reason.view(), sink);
      return;
    }
    begin_handshake(now, sink);
    if (!motion_.slot.active) return;
  }
  run_handshake(now, sink);
}

bool Cia402Master::run_mode_switch(core::TimePoint now, core::ControllerSink& sink) noexcept {
  const bool mapped = refs_.modes.mapped();
  if (!mapped && !mode_req_.written) {
    if (mode_req_.write == kNoRequest) {
      mode_req_.write = io_.submit_write(obj::kModesOfOperation, mode_req_.value);
    } else {
      const RequestResult r = io_.poll(mode_req_.write);
      if (r.state != RequestState::Pending) mode_req_.write = kNoRequest;  // reported: nothing to cancel
      if (r.state == RequestState::Done) {
        mode_req_.written = true;
      } else if (r.state != RequestState::Pending) {
        core::Text reason;
        reason.format("drive refused mode %s (6060h = %d): %s", mode_name(motion_.mode).data(),
                      static_cast<int>(mode_req_.value), sdo_abort_text(r.abort_code).data());
        fail_motion(reason.view(), sink);
        return false;
      }
    }
  }
  // A mode is valid only once 6061h reads it back [AKD digest §3.6].
  if ((mapped || mode_req_.written) && display_known_ && display_mode_ == mode_req_.value) {
    mode_switching_ = false;
    if (core::mode_is_cyclic(motion_.mode)) restart_cyclic_hold();
    return true;
  }
  if (now - mode_since_ > settings_.mode_confirm_timeout) {
    core::Text reason;
    if (display_known_) {
      reason.format("drive did not confirm mode %s within %lld ms (6061h still shows %d = %s)",
                    mode_name(motion_.mode).data(), ms(settings_.mode_confirm_timeout), static_cast<int>(display_mode_),
                    mode_name(from_op_mode(display_mode_)).data());
    } else {
      reason.format("drive did not confirm mode %s within %lld ms (6061h could not be read)", mode_name(motion_.mode).data(),
                    ms(settings_.mode_confirm_timeout));
    }
    fail_motion(reason.view(), sink);
  }
  return false;
}

void Cia402Master::begin_handshake(core::TimePoint now, core::ControllerSink& sink) noexcept {
  motion_.since = now;
  motion_.settle_until = cycle_ + settings_.settle_cycles;
  // The staged target has landed: from here on the drive runs (or stops) on it.
  if (motion_.slot.kind == CommandKind::Velocity) {
    set_velocity_target(motion_.cmd.target_velocity);
    if (motion_.mode == Mode::Velocity) vl_armed_ = true;
  } else if (motion_.slot.kind == CommandKind::Stop &&
             (motion_.mode == Mode::ProfileVelocity || motion_.mode == Mode::Velocity)) {
    set_velocity_target(0);
  }
  switch (motion_.slot.kind) {
    case CommandKind::Move:
    case CommandKind::Home:
      motion_.phase = Phase::WaitAckClear;
      break;
    case CommandKind::Stop:
      if (core::mode_is_cyclic(motion_.mode) || motion_.mode == Mode::None) {
        finish_motion(sink);
        return;
      }
      motion_.phase = Phase::WaitDone;
      break;
    default:
      motion_.phase = Phase::WaitDone;
      break;
  }
}

void Cia402Master::run_handshake(core::TimePoint now, core::ControllerSink& sink) noexcept {
  const StatusFlags f = decode_flags(statusword_);
  const core::Duration elapsed = now - motion_.since;
  const bool homing = motion_.slot.kind == CommandKind::Home;

  if (motion_.phase == Phase::WaitAckClear) {
    // The rising edge needs bit 4 low in what the drive last got; a pp drive ignores a new set-point
    // while bit 12 still acknowledges the previous one [NORD digest §5.1]. In hm bit 12 means
    // "homing attained" and may be left over from an earlier run, so it does not block the start.
    const bool edge_ready = (last_cw_ & cw::kNewSetpoint) == 0 && (homing || !f.bit12);
    if (edge_ready) {
      bit4_ = true;
      motion_.since = now;
      motion_.settle_until = cycle_ + settings_.settle_cycles;
      motion_.phase = homing ? Phase::WaitDone : Phase::WaitAck;
      return;
    }
    if (elapsed > settings_.setpoint_ack_timeout) {
      core::Text reason;
      reason.format("drive still acknowledges the previous set-point (statusword bit 12) after %lld ms",
                    ms(settings_.setpoint_ack_timeout));
      fail_motion(reason.view(), sink);
    }
    return;
  }
  if (motion_.phase == Phase::WaitAck) {
    if (f.bit12 && (last_cw_ & cw::kNewSetpoint) != 0) {
      bit4_ = false;  // the drive took the set-point [AKD digest §10.2 step 4]
      motion_.since = now;
      motion_.settle_until = cycle_ + settings_.settle_cycles;
      motion_.phase = Phase::WaitDone;
      return;
    }
    if (elapsed > settings_.setpoint_ack_timeout) {
      core::Text reason;
      reason.format("drive did not acknowledge the new set-point (statusword bit 12) within %lld ms",
                    ms(settings_.setpoint_ack_timeout));
      fail_motion(reason.view(), sink);
    }
    return;
  }
  // WaitDone
  if (homing) {
    if (f.bit13 && cycle_ >= motion_.settle_until) {
      core::Text reason;
      reason.format("homing error (method %d)", static_cast<int>(motion_.cmd.homing_method));
      fail_motion(reason.view(), sink);
      return;
    }
    if (elapsed > settings_.homing_timeout) {
      core::Text reason;
      reason.format("homing did not finish within %lld ms (method %d)", ms(settings_.homing_timeout),
                    static_cast<int>(motion_.cmd.homing_method));
      fail_motion(reason.view(), sink);
      return;
    }
  }
  if (motion_done()) finish_motion(sink);
}

bool Cia402Master::motion_done() const noexcept {
  if (cycle_ < motion_.settle_until) return false;  // status may still describe the previous target
  const StatusFlags f = decode_flags(statusword_);
  const auto vl_at = [this](std::int64_t target) {
    if (!refs_.vl_velocity_actual.mapped()) return true;  // nothing better to go on
    return std::llabs(io_.read(refs_.vl_velocity_actual) - target) <= settings_.vl_velocity_window;
  };
  switch (motion_.slot.kind) {
    case CommandKind::Move: return f.target_reached && !f.bit12;
    case CommandKind::Home: return f.bit12 && f.target_reached && !f.bit13;  // 0x1637 [AKD digest §9.3]
    case CommandKind::Velocity:
      return motion_.mode == Mode::Velocity ? vl_at(motion_.cmd.target_velocity) : f.target_reached;
    case CommandKind::Torque: return !settings_.torque_reached_bit || f.target_reached;
    case CommandKind::Stop:
      switch (motion_.mode) {
        case Mode::Velocity: return vl_at(0);
        case Mode::ProfileTorque: return !settings_.torque_reached_bit || f.target_reached;
        default: return f.target_reached;  // pv velocity 0 reached; pp/hm with halt: standstill
      }
    default: return true;
  }
}

void Cia402Master::finish_motion(core::ControllerSink& sink) noexcept {
  if (motion_.slot.kind == CommandKind::Home) homed_ = true;
  bit4_ = false;  // hm: clear bit 4 after success [AKD digest §9.3]
  motion_.slot.complete(sink);
}

void Cia402Master::fail_motion(std::string_view reason, core::ControllerSink& sink) noexcept {
  bit4_ = false;
  mode_switching_ = false;
  abandon_motion_requests();
  motion_.slot.fail(reason, sink);
}

void Cia402Master::abandon_motion_requests() noexcept {
  batch_.clear(io_);
  io_.cancel(mode_req_.write);
  mode_req_.write = kNoRequest;
}

void Cia402Master::set_velocity_target(std::int64_t value) noexcept {
  velocity_target_ = value;
  velocity_settle_until_ = cycle_ + settings_.settle_cycles;  // bit 10 may still describe the old target
}

void Cia402Master::write_safe_holds() noexcept {
  // Targets stay in the image through disable, quick stop, fault and link loss (the bus keeps
  // sending them); a later bare enable would resume the old motion.
  const auto write_if = [this](ImageRef ref, std::int64_t v) {
    if (ref.mapped()) io_.write(ref, v);
  };
  write_if(refs_.target_velocity, 0);
  write_if(refs_.target_torque, 0);
  write_if(refs_.vl_target_velocity, 0);
  // An acyclically written target stays in the drive: the standstill check must not assume 0.
  if (refs_.target_velocity.mapped() || refs_.vl_target_velocity.mapped()) set_velocity_target(0);
  vl_armed_ = false;
  restart_cyclic_hold();
  if (!refs_.position_actual.mapped()) return;
  hold_position_ = static_cast<std::int32_t>(io_.read(refs_.position_actual));
  switch (from_op_mode(mode_switching_ ? mode_req_.value : display_mode_)) {
    case Mode::CyclicPosition: write_if(refs_.target_position, hold_position_); break;
    case Mode::InterpolatedPosition:
      if (refs_.ip_target.mapped()) {
        io_.write(refs_.ip_target, hold_position_);
        ip_target_valid_ = true;
      }
      break;
    default: break;
  }
}

void Cia402Master::run_halt(core::ControllerSink& sink) noexcept {
  if (!halt_slot_.active || cycle_ < halt_settle_until_) return;
  // With halt set, bit 10 means the axis stands still [CiA 402 §6.4.2.2].
  if (state_ == AxisState::OperationEnabled && (statusword_ & sw::kTargetReached) != 0) halt_slot_.complete(sink);
}

void Cia402Master::restart_cyclic_hold() noexcept {
  cyclic_has_setpoint_ = false;
  cyclic_hold_frozen_ = false;
  ip_target_valid_ = false;
}

void Cia402Master::hold_cyclic() noexcept {
  const Mode mode = from_op_mode(display_mode_);
  if (!core::mode_is_cyclic(mode) || mode_switching_) return;
  if (state_ != AxisState::OperationEnabled) restart_cyclic_hold();
  if (cyclic_has_setpoint_) return;
  // Until a client streams set-points the drive gets the position it stands at (captured once the
  // axis is enabled, so it does not follow a drifting axis), zero velocity or zero torque.
  const bool position_known = refs_.position_actual.mapped();
  if (!cyclic_hold_frozen_) {
    if (position_known) hold_position_ = static_cast<std::int32_t>(io_.read(refs_.position_actual));
    cyclic_hold_frozen_ = state_ == AxisState::OperationEnabled;
  }
  const auto write_if = [this](ImageRef ref, std::int64_t v) {
    if (ref.mapped()) io_.write(ref, v);
  };
  switch (mode) {
    case Mode::InterpolatedPosition:
      // Bit 4 (enable interpolation) goes out only once 60C1h:1 holds where the axis stands.
      if (position_known && refs_.ip_target.mapped()) {
        io_.write(refs_.ip_target, hold_position_);
        ip_target_valid_ = true;
      }
      break;
    case Mode::CyclicPosition: write_if(refs_.target_position, hold_position_); break;
    case Mode::CyclicVelocity: write_if(refs_.target_velocity, 0); break;
    default: write_if(refs_.target_torque, 0); break;
  }
}

}  // namespace drivegate::cia402
