#include "core/axis_runner.hpp"

#include <chrono>
#include <cmath>

#include "core/command_validation.hpp"

namespace drivegate::core {

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

  const Conversion conv = validate_and_convert(spec_, cmd, snapshot_.position);
  if (!conv.ok) {
    send_reply(cmd.id, ReplyStatus::Rejected, conv.reason.view());
    return;
  }

  // A controller may finish a trivial command inside submit(); completed()/failed() then queue
  // Accepted first so that every command's replies arrive in order.
  submitting_ = cmd.id;
  accepted_sent_ = false;
  const Admission adm = controller_.submit(conv.drive, now, *this);
  submitting_ = 0;
  if (!adm.accepted) {
    send_reply(cmd.id, ReplyStatus::Rejected, adm.reason.view());
    return;
  }
  if (!accepted_sent_) send_reply(cmd.id, ReplyStatus::Accepted, {});

  if (!is_internal(cmd.id)) active_command_ = cmd.id;
  switch (cmd.kind) {
    case CommandKind::Velocity:
    case CommandKind::Torque:
      live_armed_ = true;
      last_activity_ = now;
      break;
    case CommandKind::SetMode:
      live_armed_ = mode_is_cyclic(cmd.mode);
      last_activity_ = now;
      break;
    case CommandKind::Move:
    case CommandKind::Home:
    case CommandKind::Stop:
    case CommandKind::Disable:
    case CommandKind::QuickStop:
    case CommandKind::Halt:
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
  Text why;
  const auto d = convert_setpoint(spec_, mode, sp, why);
  if (!d) {
    // Set-points stream at cycle rate: count the drop; report the first of a run as a warning
    // so the log is not flooded.
    if (rejected_setpoints_++ % 1000 == 0) emit(EventKind::Warning, 0, why.view());
    return;
  }
  controller_.setpoint(*d, now);
  if (mode_needs_live_source(mode)) {
    // A set-point keeps a live mode alive, and (re)arms the timeout for streamed cyclic modes.
    if (mode_is_cyclic(mode)) live_armed_ = true;
    last_activity_ = now;
  }
}

void AxisRunner::parameter(const ParamRequest& req, TimePoint now, RunnerOutput& out) noexcept {
  out_ = &out;
  now_ = now;
  const Admission adm = controller_.parameter(req, now);
  if (!adm.accepted) {
    ParamReply r;
    r.id = req.id;
    r.axis = index_;
    r.ok = false;
    r.error = adm.reason;
    out.parameter_reply(r);
  }
}

void AxisRunner::observe_link(TimePoint now, LinkState link, RunnerOutput& out) noexcept {
  out_ = &out;
  now_ = now;
  if (link != last_link_) {
    Text t;
    t.format("link %s -> %s", to_string(last_link_).data(), to_string(link).data());
    const bool was_up = last_link_ == LinkState::Operational;
    last_link_ = link;
    if (link == LinkState::Operational) {
      default_mode_pending_ = true;
      default_mode_attempts_ = 0;
    }
    emit(EventKind::LinkChanged, 0, t.view());
    if (was_up) {
      live_armed_ = false;
      controller_.link_lost(now, *this);
    }
  }
}

void AxisRunner::update(TimePoint now, RunnerOutput& out) noexcept {
  out_ = &out;
  now_ = now;
  ++cycle_;
  controller_.update(now, *this);
  select_default_mode(now);
  check_command_timeout(now);
  build_snapshot(now);
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

void AxisRunner::check_command_timeout(TimePoint now) noexcept {
  const DriveFeedback& fb = controller_.feedback();
  if (!live_armed_) return;
  if (fb.state != AxisState::OperationEnabled) {
    live_armed_ = false;  // nothing to stop any more
    return;
  }
  if (spec_.command_timeout <= Duration::zero() || now - last_activity_ <= spec_.command_timeout) return;

  live_armed_ = false;
  DriveCommand stop;
  stop.id = next_internal_++;
  stop.kind = spec_.timeout_stop == TimeoutStop::Halt ? CommandKind::Stop : CommandKind::QuickStop;
  const auto silent_ms = std::chrono::duration_cast<std::chrono::milliseconds>(now - last_activity_).count();
  const auto limit_ms = std::chrono::duration_cast<std::chrono::milliseconds>(spec_.command_timeout).count();
  Text t;
  t.format("no command or set-point for %lld ms (command timeout %lld ms) in %s: %s", static_cast<long long>(silent_ms),
           static_cast<long long>(limit_ms), to_string(fb.mode).data(),
           stop.kind == CommandKind::Stop ? "stopping the axis" : "quick stop");
  emit(EventKind::CommandTimeout, 0, t.view());
  const Admission adm = controller_.submit(stop, now, *this);
  if (!adm.accepted) {
    Text why;
    why.format("command timeout stop was refused by the profile: %s", adm.reason.c_str());
    emit(EventKind::Warning, 0, why.view());
  }
}

void AxisRunner::build_snapshot(TimePoint now) noexcept {
  const DriveFeedback& fb = controller_.feedback();
  const UnitConverter& u = spec_.units;
  AxisSnapshot& s = snapshot_;
  s.axis = index_;
  s.link = last_link_;
  s.state = fb.valid ? fb.state : AxisState::Unknown;
  s.mode = fb.mode;
  s.position = u.position_to_user(fb.position);
  s.velocity = u.velocity_to_user(fb.velocity);
  s.torque = u.torque_to_user(fb.torque);
  s.fault_code = fb.fault_code;
  s.fault_text = fb.fault_text;
  s.target_reached = fb.target_reached;
  s.homed = fb.homed;
  s.warning = fb.warning;
  s.stopping = fb.stopping;
  s.following_error = fb.following_error;
  s.statusword = fb.statusword;
  s.active_command = active_command_;
  s.stamp_ns = to_ns(now);
  s.cycle = cycle_;

  if (fb.valid && fb.state != last_state_) {
    Text t;
    t.format("%s -> %s", to_string(last_state_).data(), to_string(fb.state).data());
    last_state_ = fb.state;
    emit(EventKind::StateChanged, 0, t.view());
  }
  if (fb.valid && fb.mode != last_mode_) {
    Text t;
    t.format("mode %s", to_string(fb.mode).data());
    last_mode_ = fb.mode;
    emit(EventKind::ModeChanged, 0, t.view());
  }
}

void AxisRunner::completed(CommandId id) noexcept {
  if (id == submitting_ && !accepted_sent_) {
    send_reply(id, ReplyStatus::Accepted, {});
    accepted_sent_ = true;
  }
  if (id == active_command_) active_command_ = 0;
  send_reply(id, ReplyStatus::Completed, {});
}

void AxisRunner::failed(CommandId id, std::string_view reason) noexcept {
  if (id == submitting_ && !accepted_sent_) {
    send_reply(id, ReplyStatus::Accepted, {});
    accepted_sent_ = true;
  }
  if (id == active_command_) active_command_ = 0;
  send_reply(id, ReplyStatus::Failed, reason);
}

void AxisRunner::event(EventKind kind, std::uint32_t code, std::string_view text) noexcept {
  // The runner reports state and mode changes itself from the feedback; the controller's own
  // state-change events would duplicate them.
  if (kind == EventKind::StateChanged || kind == EventKind::ModeChanged) return;
  emit(kind, code, text);
}

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
