// Cia402Master: construction, command admission and bookkeeping, set-points, parameters, link loss.
#include "profiles/cia402/cia402_master.hpp"

#include <cstdint>

#include "profiles/cia402/controlword.hpp"
#include "profiles/cia402/master_helpers.hpp"
#include "profiles/cia402/op_modes.hpp"
#include "profiles/cia402/statusword.hpp"

namespace drivegate::cia402 {

using core::Admission;
using core::AxisState;
using core::CommandKind;
using core::Mode;

Cia402Master::Cia402Master(ObjectAccess& io, const MasterSettings& settings) noexcept
    : io_(io), settings_(settings), device_(settings.enable_step_timeout) {
  resolve_refs();
}

void Cia402Master::resolve_refs() noexcept {
  refs_.generation = io_.mapping_generation();
  refs_.statusword = io_.resolve(obj::kStatusword.id);
  refs_.display = io_.resolve(obj::kModesOfOperationDisplay.id);
  refs_.modes = io_.resolve(obj::kModesOfOperation.id);
  refs_.controlword = io_.resolve(obj::kControlword.id);
  refs_.error_code = io_.resolve(obj::kErrorCode.id);
  refs_.position_actual = io_.resolve(obj::kPositionActual.id);
  refs_.velocity_actual = io_.resolve(obj::kVelocityActual.id);
  refs_.vl_velocity_actual = io_.resolve(obj::kVlVelocityActual.id);
  refs_.torque_actual = io_.resolve(obj::kTorqueActual.id);
  refs_.target_position = io_.resolve(obj::kTargetPosition.id);
  refs_.target_velocity = io_.resolve(obj::kTargetVelocity.id);
  refs_.target_torque = io_.resolve(obj::kTargetTorque.id);
  refs_.vl_target_velocity = io_.resolve(obj::kVlTargetVelocity.id);
  refs_.ip_target = io_.resolve(obj::kIpDataRecord.id);
}

Mode Cia402Master::motion_mode(const core::DriveCommand& cmd) const noexcept {
  switch (cmd.kind) {
    case CommandKind::Move: return Mode::ProfilePosition;
    case CommandKind::Velocity: return cmd.mode == Mode::Velocity ? Mode::Velocity : Mode::ProfileVelocity;
    case CommandKind::Torque: return Mode::ProfileTorque;
    case CommandKind::Home: return Mode::Homing;
    case CommandKind::Stop: return from_op_mode(display_mode_);
    default: return cmd.mode;
  }
}

bool Cia402Master::at_standstill() const noexcept {
  if (state_ != AxisState::OperationEnabled && state_ != AxisState::QuickStopActive) return true;  // no torque
  const Mode mode = from_op_mode(display_mode_);
  const ImageRef vel = mode == Mode::Velocity ? refs_.vl_velocity_actual : refs_.velocity_actual;
  if (vel.mapped()) {
    const std::int64_t v = io_.read(vel);
    return v >= -settings_.standstill_velocity && v <= settings_.standstill_velocity;
  }
  // No velocity in the image: bit 10 says standstill only where it means "target reached" at rest:
  // after the quick stop ramp, with halt set [CiA 402 §6.4.2.2], and in pp/hm once no move or
  // homing run is in flight. In pv it means "velocity reached", which is standstill only when the
  // target is 0; in tq, vl and csv/cst it says nothing about the speed.
  const bool reached = (statusword_ & sw::kTargetReached) != 0;
  if (state_ == AxisState::QuickStopActive) return reached;
  if (halt_ && cycle_ >= halt_settle_until_) return reached;
  const bool moving_command =
      motion_.slot.active && (motion_.slot.kind == CommandKind::Move || motion_.slot.kind == CommandKind::Home);
  switch (mode) {
    case Mode::ProfilePosition:
    case Mode::Homing: return reached && !moving_command;
    case Mode::ProfileVelocity: return velocity_target_ == 0 && cycle_ >= velocity_settle_until_ && reached;
    // Holding the position the axis stood at (no client set-points since enable or stop).
    case Mode::InterpolatedPosition:
    case Mode::CyclicPosition: return !cyclic_has_setpoint_ && cyclic_hold_frozen_;
    default: return false;
  }
}

bool Cia402Master::profile_owns(ObjectId id) const noexcept {
  // Whatever travels in the cyclic image is overwritten by it; the controlword and mode are the
  // state machine's; a target written behind the profile's back moves the axis without a command
  // (and without the command timeout that stops it).
  if (io_.mapped(id)) return true;
  switch (id.index) {
    case 0x6040: case 0x6060: case 0x607A: case 0x60FF: case 0x6071: case 0x6042: case 0x60C1: return true;
    default: break;
  }
  if (!motion_.slot.active) return false;
  // Ramps, profile velocity, quick stop option and homing parameters the command in flight staged
  // or relies on.
  switch (id.index) {
    case 0x605A: case 0x6081: case 0x6083: case 0x6084: case 0x6087:
    case 0x607C: case 0x6098: case 0x6099: case 0x609A: return true;
    default: return false;
  }
}

Admission Cia402Master::admit_motion(const core::DriveCommand& cmd, Mode mode) const noexcept {
  Admission no;
  no.accepted = false;
  if (in_fault(state_)) return Admission::reject("axis is in fault: send fault_reset first");
  if (!to_op_mode(mode)) {
    no.reason.format("mode %s is not a CiA 402 mode", mode_name(mode).data());
    return no;
  }
  if (cmd.kind != CommandKind::Stop && core::mode_is_cyclic(mode)) {
    // The cyclic modes follow what the image holds from the first cycle on: without the target
    // in the image the drive would chase a stale or zero target [AKD digest §8.3].
    const char* needs = nullptr;
    switch (mode) {
      case Mode::InterpolatedPosition:
        if (!refs_.ip_target.mapped()) needs = "60C1h:1";
        break;
      case Mode::CyclicPosition:
        if (!refs_.target_position.mapped()) needs = "607Ah";
        break;
      case Mode::CyclicVelocity:
        if (!refs_.target_velocity.mapped()) needs = "60FFh";
        break;
      default:
        if (!refs_.target_torque.mapped()) needs = "6071h";
        break;
    }
    // Position modes start from the position the axis stands at, which only 6064h tells.
    if (needs == nullptr && (mode == Mode::InterpolatedPosition || mode == Mode::CyclicPosition) &&
        !refs_.position_actual.mapped()) {
      needs = "6064h";
    }
    if (needs != nullptr) {
      const char* name = mode == Mode::InterpolatedPosition ? "interpolated position"
                         : mode == Mode::CyclicPosition     ? "cyclic synchronous position"
                         : mode == Mode::CyclicVelocity     ? "cyclic synchronous velocity"
                                                            : "cyclic synchronous torque";
      no.reason.format("%s needs %s in the cyclic image", name, needs);
      return no;
    }
  }
  if (cmd.kind != CommandKind::SetMode) {
    if (cmd.mode != Mode::None && cmd.mode != mode && cmd.kind != CommandKind::Stop) {
      no.reason.format("%s runs in %s, not in %s", core::to_string(cmd.kind).data(), mode_name(mode).data(),
                       mode_name(cmd.mode).data());
      return no;
    }
    if (state_ == AxisState::QuickStopActive) return Admission::reject("axis is in quick stop: send enable first");
    if (state_ != AxisState::OperationEnabled) return Admission::reject("axis is not enabled: send enable first");
    if (mode == Mode::Velocity && cmd.kind == CommandKind::Velocity &&
        (cmd.target_velocity < INT16_MIN || cmd.target_velocity > INT16_MAX)) {
      // 6042h is INTEGER16 [NORD digest §5.2]; clamping would move at a speed nobody asked for.
      no.reason.format("velocity %d does not fit vl target 6042h (INTEGER16)", static_cast<int>(cmd.target_velocity));
      return no;
    }
  }
  const Mode drive_mode = from_op_mode(display_mode_);
  if (mode != drive_mode && !at_standstill()) {
    // Mode changes only at standstill [AKD digest §3.6 WARNING].
    no.reason.format("axis is moving: stop it before changing mode from %s to %s", mode_name(drive_mode).data(),
                     mode_name(mode).data());
    return no;
  }
  return Admission::accept();
}

Admission Cia402Master::submit(const core::DriveCommand& cmd, core::TimePoint now, core::ControllerSink& sink) noexcept {
  follow_mapping();
  if (!status_valid_) return Admission::reject("no status from the drive yet: wait for the link to come up");
  const Slot incoming{true, cmd.id, cmd.kind};
  switch (cmd.kind) {
    case CommandKind::Enable:
      if (in_fault(state_)) return Admission::reject("axis is in fault: send fault_reset first");
      device_slot_.abort(cmd, sink);
      device_.start(DeviceGoal::Enable, state_, now);
      device_slot_ = incoming;
      if (state_ != AxisState::OperationEnabled) write_safe_holds();  // a walk starts: no old motion
      return Admission::accept();

    case CommandKind::Disable:
    case CommandKind::QuickStop:
      device_slot_.abort(cmd, sink);
      motion_.slot.abort(cmd, sink);
      halt_slot_.abort(cmd, sink);
      abandon_motion_requests();
      mode_switching_ = false;
      bit4_ = false;
      halt_ = false;
      write_safe_holds();
      if (cmd.kind == CommandKind::Disable && (in_fault(state_) || state_ == AxisState::NotReadyToSwitchOn)) {
        // The power stage is already off [AKD digest §3.2, §3.7]: keep 0x0000 (no fault reset edge).
        device_.hold(cw::kDisableVoltage);
        sink.completed(cmd.id);
        return Admission::accept();
      }
      device_.start(cmd.kind == CommandKind::Disable ? DeviceGoal::Disable : DeviceGoal::QuickStop, state_, now);
      device_slot_ = incoming;
      return Admission::accept();

    case CommandKind::FaultReset:
      if (!in_fault(state_)) {
        // Nothing to reset; an enable or disable walk in progress goes on undisturbed.
        sink.completed(cmd.id);
        return Admission::accept();
      }
      device_slot_.abort(cmd, sink);
      device_.start(DeviceGoal::FaultReset, state_, now);
      device_slot_ = incoming;
      return Admission::accept();

    case CommandKind::Halt:
      if (in_fault(state_)) return Admission::reject("axis is in fault: send fault_reset first");
      if (state_ != AxisState::OperationEnabled) return Admission::reject("axis is not enabled: send enable first");
      halt_slot_.abort(cmd, sink);
      halt_ = true;
      halt_settle_until_ = cycle_ + settings_.settle_cycles;
      halt_slot_ = incoming;
      return Admission::accept();

    case CommandKind::Resume:
      halt_slot_.abort(cmd, sink);
      halt_ = false;
      sink.completed(cmd.id);
      return Admission::accept();

    case CommandKind::RunBlock:
      return Admission::reject("run_block is a PROFIdrive command: CiA 402 drives have no traversing blocks");

    case CommandKind::Stop:
      if (state_ != AxisState::OperationEnabled) {
        sink.completed(cmd.id);  // without operation enabled the drive produces no motion to stop
        return Admission::accept();
      }
      break;
    case CommandKind::SetMode:
    case CommandKind::Move:
    case CommandKind::Velocity:
    case CommandKind::Torque:
    case CommandKind::Home:
      break;
  }

  const Mode mode = motion_mode(cmd);
  const Admission admission = admit_motion(cmd, mode);
  if (!admission.accepted) return admission;
  motion_.slot.abort(cmd, sink);  // start_motion() cancels its requests in flight
  if (cmd.kind != CommandKind::SetMode && cmd.kind != CommandKind::Stop) {
    halt_slot_.abort(cmd, sink);  // a new motion command implies resume
    halt_ = false;
  }
  start_motion(cmd, mode, now);
  return Admission::accept();
}

void Cia402Master::setpoint(const core::DriveSetpoint& sp, core::TimePoint /*now*/) noexcept {
  follow_mapping();
  const Mode mode = from_op_mode(display_mode_);
  if (!core::mode_is_cyclic(mode) || state_ != AxisState::OperationEnabled || mode_switching_) return;
  ImageRef target{};
  std::int64_t value = 0;
  switch (mode) {
    case Mode::InterpolatedPosition: target = refs_.ip_target; value = sp.position; break;
    case Mode::CyclicPosition: target = refs_.target_position; value = sp.position; break;
    case Mode::CyclicVelocity: target = refs_.target_velocity; value = sp.velocity; break;
    default: target = refs_.target_torque; value = sp.torque; break;
  }
  if (!target.mapped()) {
    ++dropped_setpoints_;  // a cyclic set-point over acyclic requests would arrive too late to matter
    return;
  }
  io_.write(target, value);
  cyclic_has_setpoint_ = true;
  if (mode == Mode::InterpolatedPosition) ip_target_valid_ = true;
}

Admission Cia402Master::parameter(const core::ParamRequest& req, core::TimePoint /*now*/) noexcept {
  Admission no;
  no.accepted = false;
  const ObjectId id{req.index, req.sub};
  if (req.write) {
    // The daemon encoded the value for its type; a request that disagrees with itself is refused
    // rather than sent cut short.
    const std::size_t fixed = core::param_type_size(req.type);
    if (req.size == 0 || req.size > req.data.size()) {
      no.reason.format("a parameter write carries 1 to %zu bytes, not %u", req.data.size(), static_cast<unsigned>(req.size));
      return no;
    }
    if (fixed != 0 && fixed != req.size) {
      no.reason.format("%u bytes do not fit a %.*s, which has %zu", static_cast<unsigned>(req.size),
                       static_cast<int>(core::param_type_cia_name(req.type).size()),
                       core::param_type_cia_name(req.type).data(), fixed);
      return no;
    }
    if (profile_owns(id)) {
      no.reason.format("%04Xh is driven by the CiA 402 profile; use the axis commands", static_cast<unsigned>(req.index));
      return no;
    }
    if (const auto owner = io_.owner_of(id); !owner.empty()) {
      no.reason.format("%04Xh:%02X is %.*s: a write would take the drive out of the gateway's control; change the "
                       "configuration instead",
                       static_cast<unsigned>(req.index), static_cast<unsigned>(req.sub),
                       static_cast<int>(owner.size()), owner.data());
      return no;
    }
  }
  for (auto& p : params_) {
    if (p.active) continue;
    p.active = true;
    ++params_active_;
    p.req = req;
    p.request = kNoRequest;
    return Admission::accept();
  }
  no.reason.format("%zu parameter requests already in flight for this axis: try again later", params_.size());
  no.busy = true;
  return no;
}

void Cia402Master::link_lost(core::TimePoint /*now*/, core::ControllerSink& sink) noexcept {
  follow_mapping();
  // A drive out of the gateway's control is being stopped and reconfigured by the adapter.
  const std::string_view kLost = control_lost_ ? std::string_view("drive stopped following the gateway's controlword: "
                                                                  "it is being stopped and reconfigured")
                                               : std::string_view("link to drive lost");
  device_slot_.fail(kLost, sink);
  motion_.slot.fail(kLost, sink);
  halt_slot_.fail(kLost, sink);
  for (auto& p : params_) {
    if (!p.active) continue;
    p.active = false;
    --params_active_;
    io_.cancel(p.request);
    core::ParamReply reply;
    reply.id = p.req.id;
    reply.axis = p.req.axis;
    reply.error = kLost;
    sink.parameter_done(reply);
  }
  // Nothing in flight is wanted any more: free the adapter's request slots.
  abandon_motion_requests();
  io_.cancel(status_read_);
  io_.cancel(display_read_);
  io_.cancel(cw_write_);
  io_.cancel(fault_read_);
  // Forget the drive; it comes back disabled (DESIGN.md §4 safety rules).
  device_.reset();
  status_valid_ = false;
  status_read_ = kNoRequest;
  state_ = AxisState::Unknown;
  display_known_ = false;
  display_read_ = kNoRequest;
  mode_switching_ = false;
  mode_out_valid_ = false;
  bit4_ = false;
  pp_bits_ = 0;
  halt_ = false;
  cw_write_ = kNoRequest;
  cw_written_valid_ = false;
  fault_event_pending_ = false;
  fault_read_ = kNoRequest;
  follow_pending_ = false;
  control_lost_ = false;
  homed_ = false;
  last_warning_ = false;
  last_remote_ = true;
  flags_seen_ = false;
  write_safe_holds();
  last_cw_ = cw::kDisableVoltage;
  if (refs_.controlword.mapped()) io_.write(refs_.controlword, cw::kDisableVoltage);
  fb_ = core::DriveFeedback{};
}

}  // namespace drivegate::cia402
