#include "core/axis_runner.hpp"

#include <chrono>
#include <cmath>

#include "core/command_validation.hpp"

namespace drivegate::core {

namespace {
// Commands that end a velocity or torque run (a new velocity or torque command included).
bool ends_live_run(CommandKind k) noexcept {
  switch (k) {
    case CommandKind::Enable:
    case CommandKind::Halt:
    case CommandKind::Resume:
    case CommandKind::FaultReset: return false;
    default: return true;
  }
}
}  // namespace

AxisRunner::AxisRunner(AxisIndex index, const AxisSpec& spec, AxisController& controller) noexcept
    : index_(index), spec_(spec), controller_(controller) {
  snapshot_.axis = index;
}

void AxisRunner::send_reply(CommandId id, ReplyStatus status, std::string_view reason) noexcept {
  if (is_internal(id) || out_ == nullptr) return;
  Reply r;
  r.id = id;
  r.axis = index_;
  r.status = status;
  r.reason.assign(reason);
  out_->reply(r);
}

void AxisRunner::command(const Command& cmd, TimePoint now, RunnerOutput& out) noexcept {
  out_ = &out;
  now_ = now;

  if (last_link_ != LinkState::Operational) {
    Text why;
    why.format("axis '%s' is not reachable: its link is %s", spec_.name.c_str(),
               to_string(last_link_).data());
    send_reply(cmd.id, ReplyStatus::Rejected, why.view());
    return;
  }

  const DriveFeedback& fb = controller_.feedback();
  const double relative_base = move_in_flight_ != 0 ? move_target_ : spec_.units.position_to_user(fb.position);
  Command c = cmd;
  // A velocity command without a mode keeps the axis in vl when it is there (a vl drive such as
  // the NORD SK 500P stays in its mode instead of switching to pv).
  if (c.kind == CommandKind::Velocity && c.mode == Mode::None && fb.mode == Mode::Velocity) c.mode = Mode::Velocity;
  const Conversion conv = validate_and_convert(spec_, c, relative_base);
  if (!conv.ok) {
    send_reply(cmd.id, ReplyStatus::Rejected, conv.reason.view());
    return;
  }

  // A controller may finish a trivial command inside submit(); completed()/failed() then queue
  // Accepted first so that every command's replies arrive in order.
  submitting_ = cmd.id;
  submitting_kind_ = cmd.kind;
  accepted_sent_ = false;
  submit_finished_ = false;
  const Admission adm = controller_.submit(conv.drive, now, *this);
  submitting_ = 0;
  if (!adm.accepted) {
    send_reply(cmd.id, ReplyStatus::Rejected, adm.reason.view());
    return;
  }
  if (!accepted_sent_) send_reply(cmd.id, ReplyStatus::Accepted, {});
  // A command that selects a mode: the axis is entering it until the command completes or fails.
  if (conv.drive.mode != Mode::None && !submit_finished_ && !is_internal(cmd.id)) {
    entering_id_ = cmd.id;
    entering_mode_ = conv.drive.mode;
  }
  // Every motion or device command takes over from a running velocity or torque command: that run
  // has ended as the client asked. Halt, resume, enable and fault reset leave it running.
  if (live_command_ != 0 && live_command_ != cmd.id && ends_live_run(cmd.kind)) {
    if (is_internal(cmd.id))
      end_live_command(ReplyStatus::Failed, gateway_stop_reason());
    else
      end_live_command(ReplyStatus::Completed, {});
  }
  if (!is_internal(cmd.id) && (cmd.kind == CommandKind::Velocity || cmd.kind == CommandKind::Torque)) {
    live_command_ = cmd.id;
    live_reached_ = false;
  }

  if (!is_internal(cmd.id)) active_command_ = cmd.id;
  if (cmd.kind == CommandKind::Move) {
    move_in_flight_ = cmd.id;
    move_target_ = cmd.relative ? relative_base + cmd.position : cmd.position;
  } else if (cmd.kind != CommandKind::Resume && cmd.kind != CommandKind::Halt) {
    move_in_flight_ = 0;
  }
  // The command timeout watches live modes (DESIGN.md §4). Only commands that bring the axis to
  // rest disarm it; everything else keeps or (re)arms it, so a halt/resume or a set_mode to the
  // running mode cannot switch the watchdog off.
  switch (cmd.kind) {
    case CommandKind::Velocity:
    case CommandKind::Torque:
      live_armed_ = true;
      last_activity_ = now;
      break;
    case CommandKind::SetMode:
      // A switch to a live mode keeps (cyclic: arms) the watchdog; the profile accepts a switch
      // to a resting mode only at standstill, so that one disarms it.
      if (mode_is_cyclic(cmd.mode)) live_armed_ = true;
      if (!mode_needs_live_source(cmd.mode)) live_armed_ = false;
      last_activity_ = now;
      break;
    case CommandKind::Resume:
      if (mode_needs_live_source(controller_.feedback().mode)) live_armed_ = true;
      last_activity_ = now;
      break;
    case CommandKind::Move:
    case CommandKind::Home:
    case CommandKind::Stop:
    case CommandKind::Disable:
    case CommandKind::QuickStop:
      live_armed_ = false;
      break;
    default:
      break;
  }
}

void AxisRunner::setpoint(const Setpoint& sp, TimePoint now, RunnerOutput& out) noexcept {
  out_ = &out;
  now_ = now;
  const Mode mode = controller_.feedback().mode;
  if (!mode_is_cyclic(mode)) {
    // In pv, vl and tq a set-point is the keep-alive of the last velocity/torque command; its
    // values are not used (the command sets the target). The same holds from the moment such a
    // command (or a switch to a cyclic mode) was accepted, while the drive still shows the mode it
    // is leaving: the keep-alives belong to the mode it is entering. Elsewhere a set-point has no
    // meaning.
    if (mode_needs_live_source(mode) || (entering_id_ != 0 && mode_needs_live_source(entering_mode_))) {
      last_activity_ = now;
    } else if (rejected_setpoints_++ % 1000 == 0) {
      Text why;
      why.format("axis '%s' is in %s, which takes no set-points (%llu dropped so far)", spec_.name.c_str(),
                 to_string(mode).data(), static_cast<unsigned long long>(rejected_setpoints_));
      emit(EventKind::Warning, 0, why.view());
    }
    return;
  }
  Text why;
  const auto d = convert_setpoint(spec_, mode, sp, why);
  if (!d) {
    // Set-points stream at cycle rate: count every drop, report one in a thousand as a warning
    // so the log is not flooded.
    if (rejected_setpoints_++ % 1000 == 0) emit(EventKind::Warning, 0, why.view());
    return;
  }
  controller_.setpoint(*d, now);
  live_armed_ = true;
  last_activity_ = now;
}

bool AxisRunner::parameter(const ParamRequest& req, TimePoint now, RunnerOutput& out) noexcept {
  out_ = &out;
  now_ = now;
  const Admission adm = controller_.parameter(req, now);
  if (!adm.accepted && adm.busy) return false;
  if (!adm.accepted) {
    ParamReply r;
    r.id = req.id;
    r.axis = index_;
    r.ok = false;
    r.error = adm.reason;
    out.parameter_reply(r);
  }
  return true;
}

void AxisRunner::observe_link(TimePoint now, LinkState link, std::string_view detail, RunnerOutput& out) noexcept {
  out_ = &out;
  now_ = now;
  if (detail != snapshot_.link_detail.view()) snapshot_.link_detail.assign(detail);
  if (!link_observed_ || link != last_link_) {
    link_observed_ = true;
    link_since_ns_ = to_ns(now);
  }
  if (link != last_link_) {
    Text t;
    if (detail.empty())
      t.format("link %s -> %s", to_string(last_link_).data(), to_string(link).data());
    else
      t.format("link %s -> %s: %.*s", to_string(last_link_).data(), to_string(link).data(),
               static_cast<int>(detail.size()), detail.data());
    const bool was_up = last_link_ == LinkState::Operational;
    last_link_ = link;
    entering_id_ = 0;
    if (link == LinkState::Operational) {
      default_mode_pending_ = true;
      default_mode_attempts_ = 0;
    }
    emit(EventKind::LinkChanged, 0, t.view());
    if (was_up) {
      live_armed_ = false;
      controller_.link_lost(now, *this);
      end_live_command(ReplyStatus::Failed, "link to drive lost");
    }
  }
}

void AxisRunner::update(TimePoint now, RunnerOutput& out, bool snapshot) noexcept {
  out_ = &out;
  now_ = now;
  ++cycle_;
  controller_.update(now, *this);
  watch_live_command();
  select_default_mode(now);
  if (snapshot) build_snapshot(now);
  check_command_timeout(now);
  check_soft_limits(now);
}

void AxisRunner::select_default_mode(TimePoint now) noexcept {
  if (!default_mode_pending_ || last_link_ != LinkState::Operational) return;
  const DriveFeedback& fb = controller_.feedback();
  if (spec_.default_mode == Mode::None || (fb.valid && fb.mode == spec_.default_mode)) {
    default_mode_pending_ = false;
    return;
  }
  if (!fb.valid) return;
  DriveCommand cmd;
  cmd.id = next_internal_++;
  cmd.kind = CommandKind::SetMode;
  cmd.mode = spec_.default_mode;
  const Admission adm = controller_.submit(cmd, now, *this);
  if (adm.accepted) {
    default_mode_pending_ = false;
  } else if (++default_mode_attempts_ == 1000) {
    // Retried every cycle while the drive is busy (e.g. a client moved it first); give up after
    // a while and say so.
    default_mode_pending_ = false;
    Text t;
    t.format("default mode %s not selected: %s", to_string(spec_.default_mode).data(), adm.reason.c_str());
    emit(EventKind::Warning, 0, t.view());
  }
}

void AxisRunner::internal_stop(CommandKind kind, TimePoint now, std::string_view why) noexcept {
  DriveCommand stop;
  stop.id = next_internal_++;
  stop.kind = kind;
  // A command of a client that the controller aborts for this stop fails with `why`.
  ending_.assign(why);
  submitting_ = stop.id;
  submitting_kind_ = kind;
  const Admission adm = controller_.submit(stop, now, *this);
  submitting_ = 0;
  end_live_command(ReplyStatus::Failed, why);
  ending_.clear();
  if (!adm.accepted) {
    Text refused;
    refused.format("the gateway's %s was refused by the profile: %s", to_string(kind).data(), adm.reason.c_str());
    emit(EventKind::Warning, 0, refused.view());
  }
}

void AxisRunner::check_command_timeout(TimePoint now) noexcept {
  const DriveFeedback& fb = controller_.feedback();
  if (!live_armed_) return;
  // Judged by the commands, not by the mode the drive shows: right after a velocity command the
  // drive may still be switching over from another mode.
  if (fb.state != AxisState::OperationEnabled) {
    live_armed_ = false;  // nothing live to stop any more
    return;
  }
  if (spec_.command_timeout <= Duration::zero() || now - last_activity_ <= spec_.command_timeout) return;

  live_armed_ = false;
  const CommandKind kind = spec_.timeout_stop == TimeoutStop::Halt ? CommandKind::Stop : CommandKind::QuickStop;
  const auto silent_ms = std::chrono::duration_cast<std::chrono::milliseconds>(now - last_activity_).count();
  const auto limit_ms = std::chrono::duration_cast<std::chrono::milliseconds>(spec_.command_timeout).count();
  Text t;
  t.format("no command or set-point for %lld ms (command timeout %lld ms) in %s: %s", static_cast<long long>(silent_ms),
           static_cast<long long>(limit_ms), to_string(fb.mode).data(),
           kind == CommandKind::Stop ? "stopping the axis" : "quick stop");
  emit(EventKind::CommandTimeout, 0, t.view());
  internal_stop(kind, now, t.view());
}

// Profile position and homing keep to the limits through the checked target; the modes that set
// a speed or a torque do not, so the position is watched: leaving the soft limits while moving
// further out quick-stops the axis. Moving back in stays possible.
void AxisRunner::check_soft_limits(TimePoint now) noexcept {
  const auto& lim = spec_.limits;
  const DriveFeedback& fb = controller_.feedback();
  if (!lim.has_position_limits() || fb.state != AxisState::OperationEnabled) {
    limit_stop_sent_ = false;
    return;
  }
  const Mode m = fb.mode;
  if (m != Mode::ProfileVelocity && m != Mode::Velocity && m != Mode::ProfileTorque && m != Mode::CyclicVelocity &&
      m != Mode::CyclicTorque)
    return;
  const double pos = spec_.units.position_to_user(fb.position);
  const double vel = spec_.units.velocity_to_user(fb.velocity);
  const bool outward = (pos > lim.max_position && vel > 0) || (pos < lim.min_position && vel < 0);
  if (!outward) {
    limit_stop_sent_ = false;
    return;
  }
  if (limit_stop_sent_) return;
  limit_stop_sent_ = true;
  live_armed_ = false;
  Text t;
  t.format("position %.6g %s is outside the soft limits [%.6g, %.6g] %s and moving out: quick stop", pos,
           spec_.user_unit.c_str(), lim.min_position, lim.max_position, spec_.user_unit.c_str());
  emit(EventKind::Warning, 0, t.view());
  internal_stop(CommandKind::QuickStop, now, t.view());
}

AxisState AxisRunner::state() const noexcept {
  const DriveFeedback& fb = controller_.feedback();
  return fb.valid ? fb.state : AxisState::Unknown;
}

void AxisRunner::build_snapshot(TimePoint now) noexcept {
  const DriveFeedback& fb = controller_.feedback();
  const UnitConverter& u = spec_.units;
  AxisSnapshot& s = snapshot_;
  s.axis = index_;
  s.link = last_link_;
  s.link_since_ns = link_since_ns_;
  s.state = state();
  s.mode = fb.mode;
  s.position = u.position_to_user(fb.position);
  s.velocity = u.velocity_to_user(fb.velocity);
  s.torque = u.torque_to_user(fb.torque);
  s.fault_code = fb.fault_code;
  if (s.fault_text.view() != fb.fault_text.view()) s.fault_text = fb.fault_text;  // copied only when it changed
  s.target_reached = fb.target_reached;
  s.homed = fb.homed;
  s.warning = fb.warning;
  s.stopping = fb.stopping;
  s.following_error = fb.following_error;
  s.statusword = fb.statusword;
  s.active_command = active_command_;
  s.stamp_ns = to_ns(now);
  s.cycle = cycle_;

}

void AxisRunner::completed(CommandId id) noexcept {
  if (id == submitting_ && !accepted_sent_) {
    send_reply(id, ReplyStatus::Accepted, {});
    accepted_sent_ = true;
  }
  if (id == submitting_) submit_finished_ = true;
  if (id == move_in_flight_) move_in_flight_ = 0;
  if (id == entering_id_) entering_id_ = 0;  // the drive is in its mode now
  if (id == live_command_) {
    // The drive runs at the commanded speed or torque: the run goes on until something ends it.
    live_reached_ = true;
    return;
  }
  if (id == active_command_) active_command_ = 0;
  send_reply(id, ReplyStatus::Completed, {});
}

void AxisRunner::failed(CommandId id, std::string_view reason) noexcept {
  if (id == submitting_ && !accepted_sent_) {
    send_reply(id, ReplyStatus::Accepted, {});
    accepted_sent_ = true;
  }
  if (id == submitting_) submit_finished_ = true;
  if (id == entering_id_) entering_id_ = 0;  // the switch did not happen
  if (id == move_in_flight_) move_in_flight_ = 0;
  if (id == active_command_) active_command_ = 0;
  if (id == live_command_) {
    live_command_ = 0;
    // Aborted by a later command of a client: that run ended as asked. Stopped by the gateway
    // itself: the gateway's reason, not the internal command that carried the stop out.
    if (submitting_ != 0 && id != submitting_ && ends_live_run(submitting_kind_)) {
      if (!is_internal(submitting_)) return send_reply(id, ReplyStatus::Completed, {});
      return send_reply(id, ReplyStatus::Failed,
                        gateway_stop_reason());
    }
  }
  send_reply(id, ReplyStatus::Failed, reason);
}

std::string_view AxisRunner::gateway_stop_reason() const noexcept {
  return ending_.empty() ? std::string_view("stopped by the gateway") : ending_.view();
}

void AxisRunner::end_live_command(ReplyStatus status, std::string_view reason) noexcept {
  if (live_command_ == 0) return;
  const CommandId id = live_command_;
  live_command_ = 0;
  if (id == active_command_) active_command_ = 0;
  // Still in the controller's hands: the controller reports its end itself (failed() above).
  if (!live_reached_) return;
  send_reply(id, status, reason);
}

// A run the drive gave up by itself (fault, quick stop, power stage off) has failed.
void AxisRunner::watch_live_command() noexcept {
  if (live_command_ == 0 || !live_reached_) return;
  const DriveFeedback& fb = controller_.feedback();
  if (fb.state == AxisState::OperationEnabled) return;
  Text why;
  if (fb.state == AxisState::Fault || fb.state == AxisState::FaultReactionActive)
    why.format("drive left operation_enabled: %s%s%s", to_string(fb.state).data(), fb.fault_text.empty() ? "" : ": ",
               fb.fault_text.c_str());
  else
    why.format("drive left operation_enabled: now %s", to_string(fb.state).data());
  end_live_command(ReplyStatus::Failed, why.view());
}

void AxisRunner::event(EventKind kind, std::uint32_t code, std::string_view text) noexcept { emit(kind, code, text); }

void AxisRunner::parameter_done(const ParamReply& reply) noexcept {
  if (out_ == nullptr) return;
  ParamReply r = reply;
  r.axis = index_;
  out_->parameter_reply(r);
}

void AxisRunner::emit(EventKind kind, std::uint32_t code, std::string_view text) noexcept {
  if (out_ == nullptr) return;
  Event e;
  e.axis = index_;
  e.kind = kind;
  e.state = controller_.feedback().state;
  e.code = code;
  e.text.assign(text);
  e.stamp_ns = to_ns(now_);
  out_->event(e);
}

}  // namespace drivegate::core
