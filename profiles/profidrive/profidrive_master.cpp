// ProfidriveMaster: construction, command admission and bookkeeping, set-points, parameter
// admission, link loss.
#include "profiles/profidrive/profidrive_master.hpp"

#include <cstdlib>

#include "profiles/profidrive/master_helpers.hpp"
#include "profiles/profidrive/scaling.hpp"

namespace drivegate::profidrive {

using core::Admission;
using core::AxisState;
using core::CommandKind;
using core::Mode;

TelegramCapabilities capabilities_of(const TelegramLayout& layout) noexcept {
  TelegramCapabilities c;
  c.speed = layout.carries(Signal::NsollA);
  c.position = layout.carries(Signal::Satzanw);
  c.mdi = c.position && layout.carries(Signal::MdiTarpos) && layout.carries(Signal::MdiVelocity) &&
          layout.carries(Signal::MdiAcc) && layout.carries(Signal::MdiDec) && layout.carries(Signal::MdiMod);
  c.home_dist = layout.carries(Signal::HomeDist);
  c.home_mode = layout.carries(Signal::HomeMode);
  c.position_actual = layout.carries(Signal::XistA);
  // A free layout with both NSOLL_A and SATZANW runs in the operating mode PNU 930 selects [§24
  // step 8]; the master takes it as position mode, where SATZANW and the bit 6 edge mean something.
  if (c.position) c.speed = false;
  return c;
}

ProfidriveMaster::ProfidriveMaster(TelegramPort& port, ParamChannel& channel, const TelegramLayout& layout,
                                   const MasterSettings& settings) noexcept
    : port_(port),
      channel_(channel),
      layout_(layout),
      caps_(capabilities_of(layout)),
      settings_(settings),
      derived_velocity_(settings.velocity_per_count) {
  mode_ = initial_mode();
}

Mode ProfidriveMaster::initial_mode() const noexcept {
  if (caps_.speed) return Mode::ProfileVelocity;
  if (caps_.mdi) return Mode::ProfilePosition;
  if (caps_.position) return Mode::TraversingBlock;
  return Mode::None;
}

Mode ProfidriveMaster::mode_of(const core::DriveCommand& cmd) const noexcept {
  switch (cmd.kind) {
    case CommandKind::Move: return Mode::ProfilePosition;
    case CommandKind::Velocity: return Mode::ProfileVelocity;
    case CommandKind::Torque: return Mode::ProfileTorque;
    case CommandKind::Home: return Mode::Homing;
    case CommandKind::RunBlock: return Mode::TraversingBlock;
    case CommandKind::Stop: return mode_;
    default: return cmd.mode;
  }
}

// Why the telegram cannot run `mode`, or nullptr when it can.
const char* ProfidriveMaster::missing_for(Mode mode) const noexcept {
  switch (mode) {
    case Mode::ProfileVelocity:
      return caps_.speed || caps_.mdi ? nullptr
                                      : "no speed set-point: velocity needs NSOLL_A (telegram 1, 350, 351) or the MDI "
                                        "signals for real-time jog (telegram 9, 352, 353)";
    case Mode::ProfilePosition:
      return caps_.mdi ? nullptr : "no MDI signals: move needs SATZANW and MDI_TARPOS..MDI_MOD (telegram 9, 352, 353)";
    case Mode::Homing:
      return caps_.position ? nullptr : "no position mode: home needs SATZANW (telegram 7, 9, 352, 353)";
    case Mode::TraversingBlock:
      return caps_.position ? nullptr : "no SATZANW: run_block needs telegram 7, 9, 352 or 353";
    default:
      return "no such mode: PROFIdrive on the AKD has speed mode, MDI, program mode and homing (pv, pp, tb, hm)";
  }
}

Admission ProfidriveMaster::admit_motion(const core::DriveCommand& cmd, Mode mode) const noexcept {
  Admission no;
  no.accepted = false;
  if (const char* missing = missing_for(mode); missing != nullptr) {
    no.reason.format("telegram %u carries %s", static_cast<unsigned>(layout_.number), missing);
    return no;
  }
  if (in_fault(state_.state)) return Admission::reject("axis is in fault: send fault_reset first");
  if (cmd.kind == CommandKind::SetMode) {
    if (motion_.slot.active && motion_.slot.kind != CommandKind::SetMode)
      return Admission::reject("a command is running: stop it before changing mode");
    return Admission::accept();
  }
  if (state_.state != AxisState::OperationEnabled || state_.stopping)
    return Admission::reject("axis is not enabled: send enable first");
  const bool homed = (actual_.zsw1 & zsw1::kHomed) != 0;
  switch (cmd.kind) {
    case CommandKind::Move: {
      // The AKD runs MDI and program tasks only on a homed axis [§16.2, §16.3 preconditions].
      if (!homed) return Admission::reject("axis is not homed (ZSW1 bit 11): home it first");
      if (cmd.profile_velocity == 0 || !mdi_velocity_from_native(cmd.profile_velocity)) {
        no.reason.format("move velocity %u does not fit MDI_VELOCITY (1 .. 2^31-1 drive units, below 12000 rpm)",
                         static_cast<unsigned>(cmd.profile_velocity));
        return no;
      }
      if (const char* bad = check_ramps(cmd); bad != nullptr) {
        no.reason.format("move %s", bad);
        return no;
      }
      return Admission::accept();
    }
    case CommandKind::RunBlock:
      if (!homed) return Admission::reject("axis is not homed (ZSW1 bit 11): home it first");
      if (cmd.block < 0 || cmd.block > 0x7FFF) {
        // Bit 15 of SATZANW selects MDI [§12.1, §16.3].
        no.reason.format("traversing block %d is out of range: SATZANW takes 0 .. 32767", static_cast<int>(cmd.block));
        return no;
      }
      return Admission::accept();
    case CommandKind::Home:
      if (cmd.homing_method != 0 && !caps_.home_mode) {
        no.reason.format("telegram %u carries no HOME_MODE: set the homing mode in the drive (HOME.MODE, PNU 2203) and "
                         "home with method 0",
                         static_cast<unsigned>(layout_.number));
        return no;
      }
      if (cmd.home_offset != 0 && !caps_.home_dist) {
        no.reason.format("telegram %u carries no HOME_DIST: set the homing distance in the drive (HOME.DIST, PNU 2198) "
                         "and home with offset 0",
                         static_cast<unsigned>(layout_.number));
        return no;
      }
      if (cmd.homing_method < 0) {
        no.reason.format("homing mode %d: HOME_MODE takes the AKD's HOME.MODE numbers (0 and up)",
                         static_cast<int>(cmd.homing_method));
        return no;
      }
      // Homing needs no active motion task [§16.4 precondition 3].
      if ((actual_.zsw1 & zsw1::kMotionTaskActive) != 0 && !motion_.slot.active)
        return Admission::reject("a motion task is active on the drive (ZSW1 bit 14): stop it before homing");
      return Admission::accept();
    case CommandKind::Velocity:
      if (caps_.speed) {
        if (!nsoll_from_native(cmd.target_velocity)) {
          no.reason.format("velocity %d does not fit NSOLL_A (2^15 = 12000 rpm)", static_cast<int>(cmd.target_velocity));
          return no;
        }
        return Admission::accept();
      }
      if (cmd.target_velocity != 0) {
        const auto speed = static_cast<std::uint32_t>(std::llabs(static_cast<long long>(cmd.target_velocity)));
        if (!mdi_velocity_from_native(speed)) {
          no.reason.format("velocity %d does not fit MDI_VELOCITY (below 12000 rpm)", static_cast<int>(cmd.target_velocity));
          return no;
        }
        if (const char* bad = check_ramps(cmd); bad != nullptr) {
          no.reason.format("jog %s", bad);
          return no;
        }
      }
      return Admission::accept();
    default:
      return Admission::accept();
  }
}

// MDI_ACC/MDI_DEC are 16-bit words of ~763 rpm/s each by default [§17.3]; 0 would not move.
const char* ProfidriveMaster::check_ramps(const core::DriveCommand& cmd) noexcept {
  if (cmd.profile_acceleration == 0 || !mdi_acc_from_native(cmd.profile_acceleration))
    return "acceleration does not fit MDI_ACC (1 .. 65535 units of PNU 1008's step, 763 rpm/s by default)";
  if (cmd.profile_deceleration == 0 || !mdi_acc_from_native(cmd.profile_deceleration))
    return "deceleration does not fit MDI_DEC (1 .. 65535 units of PNU 1008's step, 763 rpm/s by default)";
  return nullptr;
}

void ProfidriveMaster::start_device(DeviceGoal goal, const core::DriveCommand& cmd, core::TimePoint now) noexcept {
  goal_ = goal;
  step_state_ = state_;
  step_since_ = now;
  device_slot_ = Slot{true, cmd.id, cmd.kind};
}

void ProfidriveMaster::safe_outputs() noexcept {
  goal_ = DeviceGoal::Hold;
  hold_stw1_ = stw1_word::kQuickStop;
  device_stw1_ = stw1_word::kQuickStop;
  end_motion();
  halt_ = false;
  out_ = Setpoints{};
}

Admission ProfidriveMaster::submit(const core::DriveCommand& cmd, core::TimePoint now, core::ControllerSink& sink) noexcept {
  if (!actual_valid_) return Admission::reject("no actual telegram from the drive yet: wait for the link to come up");
  switch (cmd.kind) {
    case CommandKind::Enable:
      if (in_fault(state_.state)) return Admission::reject("axis is in fault: send fault_reset first");
      device_slot_.abort(cmd, sink);
      if (state_.state != AxisState::OperationEnabled) {
        // A walk starts from a standing drive: no set-point of an earlier session survives it.
        end_motion();
        out_ = Setpoints{};
      }
      start_device(DeviceGoal::Enable, cmd, now);
      return Admission::accept();

    case CommandKind::Disable:
    case CommandKind::QuickStop:
      device_slot_.abort(cmd, sink);
      motion_.slot.abort(cmd, sink);
      halt_slot_.abort(cmd, sink);
      safe_outputs();
      if (in_fault(state_.state)) {
        // The power stage is already off; the acknowledge stays for fault_reset.
        sink.completed(cmd.id);
        return Admission::accept();
      }
      start_device(cmd.kind == CommandKind::Disable ? DeviceGoal::Disable : DeviceGoal::QuickStop, cmd, now);
      return Admission::accept();

    case CommandKind::FaultReset:
      if (!in_fault(state_.state)) {
        sink.completed(cmd.id);  // nothing to acknowledge; a walk in progress goes on
        return Admission::accept();
      }
      device_slot_.abort(cmd, sink);
      start_device(DeviceGoal::FaultReset, cmd, now);
      // Bit 7 already high: low first, for long enough that an output frame carried it and the
      // drive took it (three more actual telegrams: two whole update times after this word).
      acknowledge_from_ = (stw1_ & stw1::kFaultAcknowledge) != 0 ? telegrams_ + 3 : telegrams_;
      return Admission::accept();

    case CommandKind::Halt:
      if (in_fault(state_.state)) return Admission::reject("axis is in fault: send fault_reset first");
      if (state_.state != AxisState::OperationEnabled) return Admission::reject("axis is not enabled: send enable first");
      halt_slot_.abort(cmd, sink);
      halt_ = true;
      halt_slot_ = Slot{true, cmd.id, cmd.kind};
      halt_settle_until_ = telegrams_ + settings_.settle_telegrams;
      return Admission::accept();

    case CommandKind::Resume:
      halt_slot_.abort(cmd, sink);
      halt_ = false;
      sink.completed(cmd.id);
      return Admission::accept();

    case CommandKind::Torque:
      return Admission::reject("PROFIdrive telegrams of the AKD carry no torque set-point: use velocity or move");

    case CommandKind::Stop:
      if (state_.state != AxisState::OperationEnabled) {
        sink.completed(cmd.id);  // without S4 the drive produces no motion to stop
        return Admission::accept();
      }
      break;
    case CommandKind::SetMode:
    case CommandKind::Move:
    case CommandKind::Velocity:
    case CommandKind::Home:
    case CommandKind::RunBlock:
      break;
  }

  const Mode mode = mode_of(cmd);
  const Admission admission = admit_motion(cmd, mode);
  if (!admission.accepted) return admission;
  motion_.slot.abort(cmd, sink);
  if (cmd.kind != CommandKind::SetMode && cmd.kind != CommandKind::Stop) {
    halt_slot_.abort(cmd, sink);  // a new motion command implies resume
    halt_ = false;
  }
  if (cmd.kind == CommandKind::SetMode) {
    // PROFIdrive has no mode switch in the telegram: the telegram and PNU 930 fix the class, and
    // the task handshake picks MDI, program mode or homing. The mode is remembered for feedback.
    mode_ = mode;
    sink.completed(cmd.id);
    return Admission::accept();
  }
  start_motion(cmd, mode, now);
  return Admission::accept();
}

void ProfidriveMaster::setpoint(const core::DriveSetpoint& /*sp*/, core::TimePoint /*now*/) noexcept {
  // No PROFIdrive mode of the AKD follows streaming set-points (no isochronous mode [§2]).
  ++dropped_setpoints_;
}

bool ProfidriveMaster::gateway_owns(std::uint16_t pnu) const noexcept {
  // The telegram's own signals (every signal is also a PNU [§11.2]) are driven by the profile;
  // the telegram configuration and the operating mode are the bus' set-up [§13, §24 step 8].
  if (find_signal(pnu) != nullptr && layout_.carries(static_cast<Signal>(pnu))) return true;
  switch (pnu) {
    case 915: case 916: case 922: case 930: case 2135: case 2157: return true;
    default: return false;
  }
}

Admission ProfidriveMaster::parameter(const core::ParamRequest& req, core::TimePoint /*now*/) noexcept {
  Admission no;
  no.accepted = false;
  if (!actual_valid_) return Admission::reject("no actual telegram from the drive yet: wait for the link to come up");
  if (req.index == 0) return Admission::reject("PNU 0 does not exist: PROFIdrive parameters are numbered from 1");
  const std::size_t fixed = core::param_type_size(req.type);
  if (req.type != core::ParamType::Unknown && fixed != 1 && fixed != 2 && fixed != 4) {
    no.reason.format("PNU %u: record 47 carries Byte, Word and DWord values only, not %.*s",
                     static_cast<unsigned>(req.index), static_cast<int>(core::param_type_cia_name(req.type).size()),
                     core::param_type_cia_name(req.type).data());
    return no;
  }
  if (req.write) {
    if (req.size != 1 && req.size != 2 && req.size != 4) {
      no.reason.format("PNU %u: a write carries 1, 2 or 4 bytes (Byte, Word, DWord), not %u",
                       static_cast<unsigned>(req.index), static_cast<unsigned>(req.size));
      return no;
    }
    if (fixed != 0 && fixed != req.size) {
      no.reason.format("PNU %u: %u bytes do not fit a %.*s", static_cast<unsigned>(req.index),
                       static_cast<unsigned>(req.size), static_cast<int>(core::param_type_cia_name(req.type).size()),
                       core::param_type_cia_name(req.type).data());
      return no;
    }
    if (gateway_owns(req.index)) {
      no.reason.format("PNU %u is part of the telegram or its configuration, driven by the gateway: use the axis "
                       "commands or change the configuration",
                       static_cast<unsigned>(req.index));
      return no;
    }
  }
  for (auto& p : params_) {
    if (p.active) continue;
    p.active = true;
    p.req = req;
    ++params_active_;
    return Admission::accept();
  }
  no.reason.format("%zu parameter requests already in flight for this axis: try again later", params_.size());
  no.busy = true;
  return no;
}

void ProfidriveMaster::drop_drive(std::string_view reason, core::ControllerSink& sink) noexcept {
  device_slot_.fail(reason, sink);
  motion_.slot.fail(reason, sink);
  halt_slot_.fail(reason, sink);
  cancel_channel();
  for (auto& p : params_) {
    if (p.active) client_reply(p, nullptr, reason, 0, sink);
  }
  fault_read_wanted_ = false;
  safe_outputs();
  // Forget the drive: it is judged afresh from its next telegram and stays disabled until a
  // client commands it (DESIGN.md §4 safety rules).
  actual_valid_ = false;
  actual_ = Actuals{};
  derived_velocity_.reset();
  velocity_ = 0;
  state_ = DriveState{};
  warning_ = false;
  control_requested_ = true;
  follow_pending_ = false;
  control_lost_ = false;
  stw1_ = stw1_word::kQuickStop;
  write_outputs();
  fb_ = core::DriveFeedback{};
  fb_.controlword = stw1_;
}

void ProfidriveMaster::link_lost(core::TimePoint /*now*/, core::ControllerSink& sink) noexcept {
  drop_drive("link to drive lost", sink);
}

}  // namespace drivegate::profidrive
