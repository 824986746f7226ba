// Cia402Master: the cycle. Inputs, state tracking and events, device control, outputs, parameters,
// feedback.

#include "profiles/cia402/cia402_master.hpp"

#include <algorithm>

#include "profiles/cia402/controlword.hpp"
#include "profiles/cia402/master_helpers.hpp"
#include "profiles/cia402/op_modes.hpp"
#include "profiles/cia402/sdo_abort.hpp"
#include "profiles/cia402/statusword.hpp"

namespace drivegate::cia402 {

using core::AxisState;
using core::EventKind;
using core::Mode;

namespace {

// The controlword `cw` tells a drive in state `s` to leave it towards less power [CiA 402 §6.4.1
// transitions 5-12]: disable operation, shutdown, quick stop or disable voltage. A drive may refuse
// to enable (no DC bus, hardware enable off); it may not refuse these.
bool demands_power_down(AxisState s, std::uint16_t cw) noexcept {
  const bool disable_voltage = (cw & 0x0002U) == 0;
  const bool quick_stop = (cw & 0x0006U) == 0x0002U;
  const bool shutdown = (cw & 0x0007U) == 0x0006U;
  const bool disable_operation = (cw & 0x000FU) == 0x0007U;
  switch (s) {
    case AxisState::OperationEnabled: return disable_voltage || quick_stop || shutdown || disable_operation;
    case AxisState::SwitchedOn: return disable_voltage || quick_stop || shutdown;
    case AxisState::ReadyToSwitchOn: return disable_voltage || quick_stop;
    case AxisState::QuickStopActive: return disable_voltage;  // transition 12
    default: return false;
  }
}

// Keeps one acyclic read of `def` in flight; true (and `value` set) when one came back.
bool poll_read(ObjectAccess& io, RequestId& request, ObjectDef def, std::int64_t& value) noexcept {
  if (request == kNoRequest) {
    request = io.submit_read(def);
    return false;
  }
  const RequestResult r = io.poll(request);
  if (r.state == RequestState::Pending) return false;
  request = kNoRequest;
  if (r.state != RequestState::Done) return false;  // retried next cycle
  value = r.value;
  return true;
}

}  // namespace

void Cia402Master::update(core::TimePoint now, core::ControllerSink& sink) noexcept {
  ++cycle_;
  follow_mapping();
  read_inputs();
  if (status_valid_) {
    track_state(now, sink);
    track_fault_code(sink);
    supervise_control(now, sink);
    run_device(now, sink);
    run_motion(now, sink);
    run_halt(sink);
    hold_cyclic();
  }
  write_outputs();
  run_parameters(sink);
  fill_feedback();
}

void Cia402Master::read_inputs() noexcept {
  std::int64_t value = 0;
  if (refs_.statusword.mapped()) {
    if (io_.inputs_fresh()) {
      statusword_ = static_cast<std::uint16_t>(io_.read(refs_.statusword));
      status_valid_ = true;
    }
  } else if (poll_read(io_, status_read_, obj::kStatusword, value)) {
    statusword_ = static_cast<std::uint16_t>(value);
    status_valid_ = true;
  }
  if (refs_.display.mapped()) {
    if (io_.inputs_fresh()) {
      display_mode_ = static_cast<std::int8_t>(io_.read(refs_.display));
      display_known_ = true;
    }
  } else if ((!display_known_ || mode_switching_) &&
             poll_read(io_, display_read_, obj::kModesOfOperationDisplay, value)) {
    display_mode_ = static_cast<std::int8_t>(value);
    display_known_ = true;
  }
}

void Cia402Master::track_state(core::TimePoint /*now*/, core::ControllerSink& sink) noexcept {
  const AxisState s = decode_state(statusword_);
  const StatusFlags flags = decode_flags(statusword_);
  const Mode mode_before = fb_.mode;
  const Mode mode_now = display_known_ ? from_op_mode(display_mode_) : Mode::None;
  if (display_known_ && mode_now != mode_before) {
    core::Text t;
    t.format("mode %s -> %s", core::to_string(mode_before).data(),
             mode_now == Mode::None ? "none or manufacturer mode" : core::to_string(mode_now).data());
    sink.event(EventKind::ModeChanged, static_cast<std::uint32_t>(static_cast<std::uint8_t>(display_mode_)), t.view());
  }

  if (s != state_) {
    const AxisState prev = state_;
    state_ = s;
    core::Text t;
    t.format("%s -> %s", core::to_string(prev).data(), core::to_string(s).data());
    sink.event(EventKind::StateChanged, static_cast<std::uint32_t>(s), t.view());
    if (in_fault(s) && !in_fault(prev)) {
      core::Text reason;
      if (refs_.error_code.mapped()) {
        const auto code = static_cast<std::uint16_t>(io_.read(refs_.error_code));
        const std::string_view text = error_code_text(code, vendor_faults_);  // vendor text: not NUL-terminated
        reason.format("drive fault 0x%04X: %.*s", static_cast<unsigned>(code), static_cast<int>(text.size()), text.data());
      } else {
        reason.assign("drive went to fault");
      }
      motion_.slot.fail(reason.view(), sink);
      halt_slot_.fail(reason.view(), sink);
      abandon_motion_requests();
      // A disable is done once the drive is in fault (power stage off): run_device() completes it.
      const bool keeps_walk = device_slot_.active && (device_slot_.kind == core::CommandKind::FaultReset ||
                                                      device_slot_.kind == core::CommandKind::Disable);
      if (!keeps_walk) {
        device_slot_.fail(reason.view(), sink);
        device_.hold(cw::kDisableVoltage);  // never re-enable by itself after the reset
      }
      mode_switching_ = false;
      bit4_ = false;
      halt_ = false;
      write_safe_holds();
      fault_event_pending_ = true;
      fault_read_ = kNoRequest;
    } else if (in_fault(prev) && !in_fault(s) && prev != AxisState::Unknown) {
      fault_event_pending_ = false;
      fb_.fault_code = 0;
      fb_.fault_text.clear();
      sink.event(EventKind::FaultCleared, 0, "fault cleared");
    } else if (prev == AxisState::OperationEnabled && !device_slot_.active) {
      // Not commanded: hardware enable lost, local control, or a drive-side stop.
      core::Text reason;
      reason.format("drive left operation enabled on its own (now %s): hardware enable lost?", core::to_string(s).data());
      if (motion_.slot.kind != core::CommandKind::SetMode) {
        motion_.slot.fail(reason.view(), sink);
        abandon_motion_requests();
      }
      halt_slot_.fail(reason.view(), sink);
      device_.hold(cw::kDisableVoltage);
      bit4_ = false;
      halt_ = false;
      write_safe_holds();
    }
  }

  if (flags_seen_ && flags.warning != last_warning_) {
    sink.event(EventKind::Warning, flags.warning ? 1U : 0U,
               flags.warning ? "drive reports a warning (statusword bit 7)" : "drive warning cleared");
  }
  if (flags_seen_ && flags.remote != last_remote_) {
    sink.event(EventKind::Info, flags.remote ? 1U : 0U,
               flags.remote ? "drive back under bus control (statusword bit 9 remote)"
                            : "drive taken over locally (statusword bit 9 remote = 0)");
  }
  last_warning_ = flags.warning;
  last_remote_ = flags.remote;
  flags_seen_ = true;
}

void Cia402Master::track_fault_code(core::ControllerSink& sink) noexcept {
  if (!fault_event_pending_) return;
  if (const DriveFaultReport report = io_.fault_report(); report.valid) {
    // The drive announced the fault itself (EMCY): code and text with its vendor details.
    if (fault_read_ != kNoRequest) io_.cancel(fault_read_);
    fault_read_ = kNoRequest;
    fault_event_pending_ = false;
    fb_.fault_code = report.code;
    fb_.fault_text.assign(report.text);
    sink.event(EventKind::Fault, report.code, fb_.fault_text.view());
    return;
  }
  std::uint16_t code = 0;
  if (refs_.error_code.mapped()) {
    code = static_cast<std::uint16_t>(io_.read(refs_.error_code));
  } else {
    if (fault_read_ == kNoRequest) {
      fault_read_ = io_.submit_read(obj::kErrorCode);
      return;
    }
    const RequestResult r = io_.poll(fault_read_);
    if (r.state == RequestState::Pending) return;
    fault_read_ = kNoRequest;
    if (r.state != RequestState::Done) {
      // Some drives have no 603Fh (NORD digest §9): report the fault without a code.
      fault_event_pending_ = false;
      fb_.fault_code = 0;
      fb_.fault_text.format("drive fault (603Fh unreadable: %s)", sdo_abort_text(r.abort_code).data());
      sink.event(EventKind::Fault, 0, fb_.fault_text.view());
      return;
    }
    code = static_cast<std::uint16_t>(r.value);
  }
  fault_event_pending_ = false;
  fb_.fault_code = code;
  fb_.fault_text.assign(error_code_text(code, vendor_faults_));
  sink.event(EventKind::Fault, code, fb_.fault_text.view());
}

void Cia402Master::run_device(core::TimePoint now, core::ControllerSink& sink) noexcept {
  const DeviceProgress p = device_.step(state_, now);
  if (p == DeviceProgress::Done) {
    device_slot_.complete(sink);
  } else if (p == DeviceProgress::Failed) {
    device_slot_.fail(device_.failure().view(), sink);
  }
}

// Whatever the cause (a mapping changed behind the gateway's back, a second master, a drive
// firmware that ignores the bus), a drive that does not follow the controlword is out of the
// gateway's control: that is an event and a safe stop by the adapter, not a stale "operational"
// (DESIGN.md §4). Judged on fresh status only, against the controlword already sent.
void Cia402Master::supervise_control(core::TimePoint now, core::ControllerSink& sink) noexcept {
  if (control_lost_) return;
  if (refs_.statusword.mapped() && !io_.inputs_fresh()) return;
  if (!demands_power_down(state_, last_cw_)) {
    follow_pending_ = false;
    return;
  }
  const std::uint16_t demand = static_cast<std::uint16_t>(last_cw_ & cw::kDeviceControlMask);
  if (!follow_pending_ || follow_state_ != state_ || follow_cw_ != demand) {
    follow_pending_ = true;
    follow_state_ = state_;
    follow_cw_ = demand;
    follow_since_ = now;
    return;
  }
  if (now - follow_since_ <= settings_.follow_timeout) return;
  control_lost_ = true;
  core::Text why;
  why.format("drive does not follow its controlword: still %s %lld ms after controlword 0x%04X told it to leave "
             "(statusword 0x%04X)",
             core::to_string(state_).data(), ms(now - follow_since_), static_cast<unsigned>(last_cw_),
             static_cast<unsigned>(statusword_));
  sink.event(EventKind::ControlLost, 0, why.view());
  io_.control_lost(why.view());
}

void Cia402Master::write_outputs() noexcept {
  std::uint16_t cw = device_.controlword();
  if (status_valid_ && state_ == AxisState::OperationEnabled && (cw & cw::kDeviceControlMask) == cw::kEnableOperation) {
    switch (from_op_mode(display_mode_)) {
      case Mode::ProfilePosition:
        if (bit4_) cw = static_cast<std::uint16_t>(cw | cw::kNewSetpoint | pp_bits_);
        break;
      case Mode::Homing:
        if (bit4_) cw = static_cast<std::uint16_t>(cw | cw::kHomingStart);
        break;
      case Mode::InterpolatedPosition:
        // Only with 60C1h:1 holding the actual position (or a set-point): otherwise the drive would
        // interpolate towards whatever the image held and jump.
        if (!mode_switching_ && ip_target_valid_) cw = static_cast<std::uint16_t>(cw | cw::kEnableInterpolation);
        break;
      case Mode::Velocity:
        // 0x007F runs from the bus set-point [NORD digest §5.2]: only for a velocity command given
        // since the last enable, never for a 6042h left over from before.
        if (vl_armed_) cw = static_cast<std::uint16_t>(cw | cw::kVlRunBits);
        break;
      default: break;
    }
    if (halt_) cw = static_cast<std::uint16_t>(cw | cw::kHalt);
  }

  if (!mode_out_valid_ && display_known_) {
    mode_out_ = display_mode_;  // mirror until a mode is chosen: a mapped 6060h must hold a valid mode
    mode_out_valid_ = true;
  }
  if (mode_out_valid_ && refs_.modes.mapped()) io_.write(refs_.modes, mode_out_);

  fb_.controlword = cw;
  if (refs_.controlword.mapped()) {
    io_.write(refs_.controlword, cw);
    last_cw_ = cw;
    return;
  }
  // Controlword over acyclic writes: one in flight, the latest value follows when it is done.
  if (cw_write_ != kNoRequest) {
    const RequestResult r = io_.poll(cw_write_);
    if (r.state == RequestState::Pending) return;
    cw_write_ = kNoRequest;
    cw_written_valid_ = r.state == RequestState::Done;
    if (cw_written_valid_) {
      cw_written_ = cw_inflight_;
      last_cw_ = cw_inflight_;
    }
  }
  if (!cw_written_valid_ || cw != cw_written_) {
    cw_write_ = io_.submit_write(obj::kControlword, cw);
    cw_inflight_ = cw;
  }
}

void Cia402Master::run_parameters(core::ControllerSink& sink) noexcept {
  if (params_active_ == 0) return;
  for (auto& p : params_) {
    if (!p.active) continue;
    const ObjectId id{p.req.index, p.req.sub};
    const std::size_t fixed = core::param_type_size(p.req.type);
    if (p.request == kNoRequest) {
      const auto expected = static_cast<std::uint8_t>(fixed <= 4 ? fixed : 0);
      p.request = p.req.write ? io_.submit_download(id, p.req.bytes()) : io_.submit_upload(id, p.req.data, expected);
      continue;  // kNoRequest again: the adapter's queue is full, retry next cycle
    }
    const RequestResult r = io_.poll(p.request);
    if (r.state == RequestState::Pending) continue;
    core::ParamReply reply;
    reply.id = p.req.id;
    reply.axis = p.req.axis;
    reply.type = p.req.type;
    const auto type_name = core::param_type_cia_name(p.req.type);
    if (r.state == RequestState::Done) {
      const std::size_t size = p.req.write ? p.req.size : std::min<std::size_t>(r.size, p.req.data.size());
      if (!p.req.write && fixed != 0 && size != fixed) {
        // Never a value cut to size or padded: the drive's object is not what the type says.
        reply.error.format("%04Xh:%02X: the drive sent %zu bytes, a %.*s has %zu", static_cast<unsigned>(id.index),
                           static_cast<unsigned>(id.sub), size, static_cast<int>(type_name.size()), type_name.data(),
                           fixed);
      } else if (!p.req.write && !r.size_known) {
        // Four bytes came, but how many of them are the object only its type says
        // (stoeber-sd6-canopen.md §6.4: expedited uploads without a size).
        reply.error.format("%04Xh:%02X: the drive did not say how long the object is (expedited upload without a "
                           "size) and its type is not known: name the type (--type u8, u16, ...)",
                           static_cast<unsigned>(id.index), static_cast<unsigned>(id.sub));
      } else {
        reply.ok = true;
        reply.size = static_cast<std::uint16_t>(size);
        std::copy_n(p.req.data.begin(), size, reply.data.begin());
      }
    } else if (r.state == RequestState::Failed) {
      reply.error_code = r.abort_code;
      reply.error.format("%04Xh:%02X: %s (abort code 0x%08X)", static_cast<unsigned>(id.index),
                         static_cast<unsigned>(id.sub), sdo_abort_text(r.abort_code).data(),
                         static_cast<unsigned>(r.abort_code));
    } else {
      reply.error.assign("request lost by the bus adapter");
    }
    p.active = false;
    --params_active_;
    sink.parameter_done(reply);
  }
}

void Cia402Master::fill_feedback() noexcept {
  fb_.valid = status_valid_;
  fb_.state = status_valid_ ? state_ : AxisState::Unknown;
  fb_.mode = display_known_ ? from_op_mode(display_mode_) : Mode::None;
  fb_.statusword = statusword_;
  const auto read_if = [this](ImageRef ref, std::int64_t fallback) {
    return ref.mapped() ? io_.read(ref) : fallback;
  };
  fb_.position = static_cast<std::int32_t>(read_if(refs_.position_actual, fb_.position));
  const ImageRef vel = fb_.mode == Mode::Velocity ? refs_.vl_velocity_actual : refs_.velocity_actual;
  fb_.velocity = static_cast<std::int32_t>(read_if(vel, fb_.velocity));
  fb_.torque = static_cast<std::int16_t>(read_if(refs_.torque_actual, fb_.torque));
  const StatusFlags f = decode_flags(statusword_);
  fb_.target_reached = f.target_reached;
  fb_.homed = homed_ || (fb_.mode == Mode::Homing && f.bit12 && !f.bit13);
  fb_.following_error = f.bit13 && fb_.mode != Mode::Homing;
  fb_.warning = f.warning;
  fb_.internal_limit = f.internal_limit;
  fb_.halted = halt_;
  fb_.stopping = state_ == AxisState::QuickStopActive || (halt_ && !f.target_reached) ||
                 (motion_.slot.active && motion_.slot.kind == core::CommandKind::Stop);
}

}  // namespace drivegate::cia402
