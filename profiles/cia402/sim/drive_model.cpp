// DriveModel: object dictionary, device control state machine, faults and 6041h.
#include "profiles/cia402/sim/drive_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>

namespace drivegate::cia402::sim {
namespace {

// Controlword commands [AKD digest §1 table; nord §3.2]. Bit 7 is only looked at in Fault.
constexpr bool cmd_disable_voltage(std::uint16_t cw) noexcept { return (cw & 0x0002U) == 0; }
constexpr bool cmd_quick_stop(std::uint16_t cw) noexcept { return (cw & 0x0006U) == 0x0002U; }
constexpr bool cmd_shutdown(std::uint16_t cw) noexcept { return (cw & 0x0007U) == 0x0006U; }
constexpr bool cmd_switch_on(std::uint16_t cw) noexcept { return (cw & 0x0007U) == 0x0007U; }  // bit 3 X
constexpr bool cmd_enable_operation(std::uint16_t cw) noexcept { return (cw & 0x000FU) == 0x000FU; }
constexpr bool cmd_disable_operation(std::uint16_t cw) noexcept { return (cw & 0x000FU) == 0x0007U; }

// 1001h bits for an error code's class [CiA 301 error register; emergency error code classes].
std::uint8_t error_register_for(std::uint16_t code) noexcept {
  std::uint8_t reg = 0x01;  // generic error
  switch (code >> 12) {
    case 0x2: reg |= 0x02; break;  // current
    case 0x3: reg |= 0x04; break;  // voltage
    case 0x4: reg |= 0x08; break;  // temperature
    case 0x8:
      if ((code & 0x0F00U) == 0x0100U) reg |= 0x10;  // communication
      else if ((code & 0x0F00U) >= 0x0600U) reg |= 0x20;  // positioning / control: device profile specific
      break;
    case 0xF: reg |= 0x80; break;  // manufacturer specific
    default: break;
  }
  return reg;
}

// 6502h: bit (mode - 1) for the standard modes 1..10 [CiA 402 supported drive modes].
std::uint32_t supported_modes_bits(const std::vector<std::int8_t>& modes) noexcept {
  std::uint32_t bits = 0;
  for (const std::int8_t m : modes) {
    if (m >= 1 && m <= 10) bits |= 1U << static_cast<unsigned>(m - 1);
  }
  return bits;
}

}  // namespace

DriveModel::DriveModel(DriveModelConfig config) : config_(std::move(config)), od_(96) {
  const double vel_per_rps =
      config_.velocity_units_per_rps > 0.0 ? config_.velocity_units_per_rps : config_.position_units_per_rev;
  vel_scale_ = vel_per_rps / config_.position_units_per_rev;
  vl_scale_ = config_.vl_units_per_rps / config_.position_units_per_rev;
  populate_dictionary();
  mode_ = static_cast<std::int8_t>(od(obj::kModesOfOperation));
  pos_ = demand_pos_ = config_.start_position;
  publish();
}

void DriveModel::populate_dictionary() {
  using A = Access;
  // Speeds and ramps derived from the axis' scaling: kept within 1..INT32_MAX drive units so that
  // no scaling the configuration accepts can make a default fall outside its object's range.
  const auto vel = [this](double rps) {
    const double v = std::round(rps * config_.position_units_per_rev * vel_scale_);
    return static_cast<std::int64_t>(std::clamp(std::isfinite(v) ? v : 1.0, 1.0, 2147483647.0));
  };
  const std::int64_t vmax = vel(config_.max_velocity_rps);
  const std::int64_t no_min = type_min(DataType::I32);
  bool ok = true;
  const auto add = [&](ObjectDef def, Access a, std::int64_t v, std::optional<std::int64_t> lo = std::nullopt,
                       std::optional<std::int64_t> hi = std::nullopt) { ok = od_.add(def, a, v, lo, hi) && ok; };
  // Communication profile [CiA 301; AKD digest §11.3].
  add({{0x1000, 0}, DataType::U32}, A::ReadOnly, config_.device_type);
  add(obj::kErrorRegister, A::ReadOnly, 0);
  add({{0x1018, 0}, DataType::U8}, A::ReadOnly, 4);
  add({{0x1018, 1}, DataType::U32}, A::ReadOnly, config_.identity.vendor_id);
  add({{0x1018, 2}, DataType::U32}, A::ReadOnly, config_.identity.product_code);
  add({{0x1018, 3}, DataType::U32}, A::ReadOnly, config_.identity.revision);
  add({{0x1018, 4}, DataType::U32}, A::ReadOnly, config_.identity.serial);
  // Device control [AKD digest §3].
  add(obj::kErrorCode, A::ReadOnly, 0);
  add(obj::kControlword, A::ReadWrite, 0);
  add(obj::kStatusword, A::ReadOnly, 0);
  add(obj::kQuickStopOption, A::ReadWrite, config_.quick_stop_option, 1, 6);  // 1, 2, 5, 6 (write_object)
  add(obj::kShutdownOption, A::ReadWrite, 0, 0, 1);         // 0 disable drive, 1 ramp then disable
  add(obj::kDisableOperationOption, A::ReadWrite, 1, 0, 1);  // 0 disable drive, 1 ramp then disable
  add(obj::kHaltOption, A::ReadWrite, 1, 1, 3);              // 1 profile dec, 2 quick-stop dec, 3 = 2
  add(obj::kFaultReactionOption, A::ReadWrite, 2, 0, 2);     // 0 coast, 1 profile dec, 2 quick-stop dec
  add(obj::kModesOfOperation, A::ReadWrite, config_.initial_mode);
  add(obj::kModesOfOperationDisplay, A::ReadOnly, config_.initial_mode);
  add(obj::kSupportedDriveModes, A::ReadOnly, supported_modes_bits(config_.supported_modes));
  // vl [nord §5.2]: ramps as delta speed per delta time (s).
  add(obj::kVlTargetVelocity, A::ReadWrite, 0);
  add(obj::kVlVelocityDemand, A::ReadOnly, 0);
  add(obj::kVlVelocityActual, A::ReadOnly, 0);
  add(obj::kVlAccelerationDeltaSpeed, A::ReadWrite, 1500);
  add(obj::kVlAccelerationDeltaTime, A::ReadWrite, 1);
  add(obj::kVlDecelerationDeltaSpeed, A::ReadWrite, 1500);
  add(obj::kVlDecelerationDeltaTime, A::ReadWrite, 1);
  // Position / velocity / torque.
  add(obj::kPositionDemand, A::ReadOnly, 0);
  add({{0x6063, 0}, DataType::I32}, A::ReadOnly, 0);  // position actual internal value
  add(obj::kPositionActual, A::ReadOnly, 0);
  add(obj::kFollowingErrorWindow, A::ReadWrite, config_.following_error_window);
  add(obj::kFollowingErrorTimeout, A::ReadWrite, config_.following_error_timeout_ms);
  add(obj::kPositionWindow, A::ReadWrite, config_.position_window);
  add(obj::kPositionWindowTime, A::ReadWrite, 0);
  add({{0x606B, 0}, DataType::I32}, A::ReadOnly, 0);  // velocity demand value
  add(obj::kVelocityActual, A::ReadOnly, 0);
  add(obj::kVelocityWindow, A::ReadWrite, config_.velocity_window);
  add(obj::kVelocityWindowTime, A::ReadWrite, 0);
  add(obj::kTargetTorque, A::ReadWrite, 0);
  add(obj::kMaxTorque, A::ReadWrite, 3000);
  add(obj::kTorqueActual, A::ReadOnly, 0);
  add(obj::kTargetPosition, A::ReadWrite, 0);
  add(obj::kHomeOffset, A::ReadWrite, 0);
  add({{0x607D, 0}, DataType::U8}, A::ReadOnly, 2);
  add(obj::kSoftwareLimitMin, A::ReadWrite, 0);
  add(obj::kSoftwareLimitMax, A::ReadWrite, 0);
  add(obj::kMaxProfileVelocity, A::ReadWrite, vmax);
  add(obj::kProfileVelocity, A::ReadWrite, vel(10.0));
  // Zero accelerations would never move or never stop: refused with "value too low".
  add(obj::kProfileAcceleration, A::ReadWrite, vel(100.0), 1);
  add(obj::kProfileDeceleration, A::ReadWrite, vel(100.0), 1);
  add(obj::kQuickStopDeceleration, A::ReadWrite, vel(1000.0), 1);
  add(obj::kTorqueSlope, A::ReadWrite, 10000, 1);
  // Homing [AKD digest §9.1]: speeds above the motor's limit are refused (0x06090031, §14 step 15).
  add(obj::kHomingMethod, A::ReadWrite, 0);
  add({{0x6099, 0}, DataType::U8}, A::ReadOnly, 2);
  add(obj::kHomingSpeedSwitch, A::ReadWrite, vel(2.0), 0, vmax);
  add(obj::kHomingSpeedZero, A::ReadWrite, vel(0.5), 0, vmax);
  add(obj::kHomingAcceleration, A::ReadWrite, vel(100.0), 1);
  // Cyclic modes and ip [AKD digest §8.2].
  add(obj::kVelocityOffset, A::ReadWrite, 0);
  add(obj::kTorqueOffset, A::ReadWrite, 0);
  add({{0x60C1, 0}, DataType::U8}, A::ReadOnly, 1);
  add(obj::kIpDataRecord, A::ReadWrite, 0);
  add({{0x60C2, 0}, DataType::U8}, A::ReadOnly, 2);
  add(obj::kIpTimePeriodUnits, A::ReadWrite, 1);
  add(obj::kIpTimePeriodIndex, A::ReadWrite, -3, -6, 0);
  add({{0x60F4, 0}, DataType::I32}, A::ReadOnly, 0);  // following error actual value
  add(obj::kDigitalInputs, A::ReadOnly, 0);
  add(obj::kTargetVelocity, A::ReadWrite, 0, no_min);
  // A broken table is a programming error in this file; fail loudly in every build type.
  if (!ok || !mode_supported(config_.initial_mode)) std::abort();
}

std::int64_t DriveModel::od(ObjectDef def) const noexcept { return od_.get(def.id).value_or(0); }

bool DriveModel::mode_supported(std::int64_t mode) const noexcept {
  if (mode == op_mode::kNone) return true;
  return std::any_of(config_.supported_modes.begin(), config_.supported_modes.end(),
                     [mode](std::int8_t m) { return m == mode; });
}

ReadResult DriveModel::read_object(ObjectId id) const noexcept { return od_.read(id); }

std::uint32_t DriveModel::write_object(ObjectId id, std::int64_t value) noexcept {
  // Checks the dictionary's type ranges cannot express.
  if (id == obj::kModesOfOperation.id && value >= type_min(DataType::I8) && value <= type_max(DataType::I8) &&
      !mode_supported(value)) {
    return abort_code::kValueRange;
  }
  if (id == obj::kQuickStopOption.id && value != 1 && value != 2 && value != 5 && value != 6) {
    return abort_code::kValueRange;  // AKD digest §3.5: 1, 2, 5, 6
  }
  const bool running = state_ == DriveState::OperationEnabled;
  if (id == obj::kHomingMethod.id && running && mode_ == op_mode::kHoming &&
      (homing_ == HomingPhase::Search || homing_ == HomingPhase::BackOff || homing_ == HomingPhase::Index ||
       homing_ == HomingPhase::MoveToHome)) {
    return abort_code::kStatePrevents;
  }
  if ((id == obj::kIpTimePeriodUnits.id || id == obj::kIpTimePeriodIndex.id) && running &&
      mode_ == op_mode::kInterpolatedPosition && (prev_cw_ & 0x0010U) != 0) {
    return abort_code::kStatePrevents;  // the period cannot change while interpolation runs
  }
  return od_.set(id, value);
}

void DriveModel::set_limit_switch_positions(std::optional<double> negative, std::optional<double> positive) noexcept {
  config_.negative_limit_position = negative;
  config_.positive_limit_position = positive;
}

bool DriveModel::negative_limit_active() const noexcept {
  return config_.negative_limit_position && physical(pos_) <= *config_.negative_limit_position;
}
bool DriveModel::positive_limit_active() const noexcept {
  return config_.positive_limit_position && physical(pos_) >= *config_.positive_limit_position;
}
bool DriveModel::home_switch_active() const noexcept {
  return config_.home_switch_position && physical(pos_) >= *config_.home_switch_position;
}

// ---------------------------------------------------------------------------------------------
// Faults and EMCY

void DriveModel::inject_fault(std::uint16_t error_code) noexcept {
  fault_cause_active_ = true;
  cause_code_ = error_code;
  pending_fault_ = error_code;
}

void DriveModel::clear_fault_cause() noexcept {
  fault_cause_active_ = false;
  pending_fault_ = 0;
}

void DriveModel::raise_fault(std::uint16_t code) noexcept {
  if (state_ == DriveState::FaultReactionActive || state_ == DriveState::Fault) return;  // first fault wins
  fault_code_ = code;
  od_.store(obj::kErrorCode.id, code);
  od_.store(obj::kErrorRegister.id, error_register_for(code));
  push_emcy(code);
  enter_state(DriveState::FaultReactionActive);  // transition 13
}

void DriveModel::push_emcy(std::uint16_t code) noexcept {
  if (emcy_count_ == kEmcyCapacity) {
    ++emcy_overflows_;
    return;
  }
  emcy_[(emcy_head_ + emcy_count_) % kEmcyCapacity] =
      EmcyEvent{code, static_cast<std::uint8_t>(od(obj::kErrorRegister))};
  ++emcy_count_;
}

std::optional<EmcyEvent> DriveModel::take_pending_emcy() noexcept {
  if (emcy_count_ == 0) return std::nullopt;
  const EmcyEvent e = emcy_[emcy_head_];
  emcy_head_ = (emcy_head_ + 1) % kEmcyCapacity;
  --emcy_count_;
  return e;
}

void DriveModel::power_cycle() noexcept {
  od_.reset_to_defaults();
  if (!config_.keep_position_on_power_cycle) {
    coord_offset_ -= pos_;  // an incremental encoder counts from 0 again
    pos_ = 0;
  }
  vel_ = 0;
  torque_ = 0;
  torque_demand_ = 0;
  demand_pos_ = pos_;
  demand_vel_ = 0;
  control_ = prev_control_ = Control::Coast;
  prev_cw_ = 0;
  fault_code_ = 0;
  pending_fault_ = 0;
  following_error_ = false;
  following_error_time_ = 0;
  oe_stop_ = OeStop::None;
  state_ = DriveState::NotReadyToSwitchOn;  // transition 0
  bits_ = ModeBits{};
  change_mode(static_cast<std::int8_t>(od(obj::kModesOfOperation)));
  publish();
}

// ---------------------------------------------------------------------------------------------
// State machine

bool DriveModel::standstill() const noexcept {
  const double threshold = 1e-2 * config_.position_units_per_rev;  // 0.01 rev/s (0.6 rpm)
  return demand_vel_ == 0.0 && std::abs(vel_) < threshold;
}

void DriveModel::enter_state(DriveState s) noexcept {
  // Entering or leaving Operation enabled restarts the mode function: set-points, buffered jobs and
  // a running homing are dropped (AKD digest §3.2 transition 11: quick stop deletes set-points).
  if (s == DriveState::OperationEnabled || state_ == DriveState::OperationEnabled) change_mode(mode_);
  state_ = s;
  oe_stop_ = OeStop::None;
}

void DriveModel::update_state(std::uint16_t cw) noexcept {
  const bool powered = state_ == DriveState::ReadyToSwitchOn || state_ == DriveState::SwitchedOn ||
                       state_ == DriveState::OperationEnabled || state_ == DriveState::QuickStopActive;
  if (pending_fault_ != 0 && state_ != DriveState::NotReadyToSwitchOn) {
    const std::uint16_t code = pending_fault_;
    pending_fault_ = 0;
    if (state_ != DriveState::FaultReactionActive && state_ != DriveState::Fault) {
      raise_fault(code);
      return;
    }
  }
  if (powered && !hardware_enable_) {
    enter_state(DriveState::SwitchOnDisabled);
    return;
  }
  switch (state_) {
    case DriveState::Unknown:             // never entered by the drive
    case DriveState::NotReadyToSwitchOn:  // transition 1: self-test done
      enter_state(DriveState::SwitchOnDisabled);
      if (fault_cause_active_) pending_fault_ = cause_code_;  // the cause outlived the power cycle
      break;
    case DriveState::SwitchOnDisabled:
      if (hardware_enable_ && cmd_shutdown(cw)) enter_state(DriveState::ReadyToSwitchOn);  // 2
      break;
    case DriveState::ReadyToSwitchOn:
      if (cmd_disable_voltage(cw) || cmd_quick_stop(cw)) enter_state(DriveState::SwitchOnDisabled);  // 7
      else if (cmd_switch_on(cw)) enter_state(DriveState::SwitchedOn);  // 3 (0x0F as well, AKD §3.2)
      break;
    case DriveState::SwitchedOn:
      if (cmd_disable_voltage(cw) || cmd_quick_stop(cw)) enter_state(DriveState::SwitchOnDisabled);  // 10
      else if (cmd_shutdown(cw)) enter_state(DriveState::ReadyToSwitchOn);  // 6
      else if (cmd_enable_operation(cw)) enter_state(DriveState::OperationEnabled);  // 4
      break;
    case DriveState::OperationEnabled:
      if (cmd_disable_voltage(cw)) {
        enter_state(DriveState::SwitchOnDisabled);  // 9: torque off at once
      } else if (cmd_quick_stop(cw)) {
        enter_state(DriveState::QuickStopActive);  // 11
      } else if (cmd_shutdown(cw)) {
        // 8, after a ramp when 605Bh = 1.
        if (od(obj::kShutdownOption) == 0 || (oe_stop_ == OeStop::Shutdown && standstill())) {
          enter_state(DriveState::ReadyToSwitchOn);
        } else {
          oe_stop_ = OeStop::Shutdown;
        }
      } else if (cmd_disable_operation(cw)) {
        // 5, after a ramp when 605Ch = 1 (AKD §3.2: stopped with the mode's ramp, holds position).
        if (od(obj::kDisableOperationOption) == 0 || (oe_stop_ == OeStop::DisableOperation && standstill())) {
          enter_state(DriveState::SwitchedOn);
        } else {
          oe_stop_ = OeStop::DisableOperation;
        }
      } else {
        oe_stop_ = OeStop::None;  // enable operation again: a pending ramp-down is cancelled
      }
      break;
    case DriveState::QuickStopActive: {
      const std::int64_t option = od(obj::kQuickStopOption);
      if (cmd_disable_voltage(cw)) {
        enter_state(DriveState::SwitchOnDisabled);  // 12
      } else if (standstill()) {
        if (option == 1 || option == 2) {
          enter_state(DriveState::SwitchOnDisabled);  // 12, automatic after the stop
        } else if (cmd_enable_operation(cw)) {
          enter_state(DriveState::OperationEnabled);  // 16, only with options 5/6
        }
      }
      break;
    }
    case DriveState::FaultReactionActive:
      if (control_ == Control::Coast || standstill()) enter_state(DriveState::Fault);  // 14
      break;
    case DriveState::Fault: {
      const bool reset_edge = (cw & 0x0080U) != 0 && (prev_cw_ & 0x0080U) == 0;
      if (reset_edge && !fault_cause_active_) {  // 15
        fault_code_ = 0;
        od_.store(obj::kErrorCode.id, 0);
        od_.store(obj::kErrorRegister.id, 0);
        push_emcy(0);
        following_error_ = false;
        following_error_time_ = 0;
        enter_state(DriveState::SwitchOnDisabled);
      }
      break;
    }
  }
}

void DriveModel::step(core::Duration dt) noexcept {
  if (dt.count() <= 0) return;
  const double dt_s = static_cast<double>(dt.count()) * 1e-9;
  const auto cw = static_cast<std::uint16_t>(od(obj::kControlword));
  const auto requested_mode = static_cast<std::int8_t>(od(obj::kModesOfOperation));
  if (requested_mode != mode_) change_mode(requested_mode);
  update_state(cw);
  run_motion(cw, dt_s);
  prev_cw_ = cw;
  publish();
}

std::uint16_t DriveModel::statusword() const noexcept { return static_cast<std::uint16_t>(od(obj::kStatusword)); }

void DriveModel::publish() noexcept {
  // State bits 6,5,3,2,1,0 [AKD digest §1 table]; bit 4 voltage enabled while the power stage may
  // be on; bit 5 (quick stop, active low) set only where the table requires it.
  std::uint16_t sw = 0;
  switch (state_) {
    case DriveState::Unknown:  // never entered by the drive
    case DriveState::NotReadyToSwitchOn: sw = 0x0000; break;
    case DriveState::SwitchOnDisabled: sw = 0x0040; break;
    case DriveState::ReadyToSwitchOn: sw = 0x0031; break;
    case DriveState::SwitchedOn: sw = 0x0033; break;
    case DriveState::OperationEnabled: sw = 0x0037; break;
    case DriveState::QuickStopActive: sw = 0x0017; break;
    case DriveState::FaultReactionActive: sw = 0x000F; break;
    case DriveState::Fault: sw = 0x0008; break;
  }
  if (warning_) sw |= 0x0080;
  sw |= 0x0200;  // remote: the bus controls the drive
  if (bits_.target_reached) sw |= 0x0400;
  if (bits_.internal_limit) sw |= 0x0800;
  if (bits_.bit12) sw |= 0x1000;
  if (bits_.bit13) sw |= 0x2000;
  od_.store(obj::kStatusword.id, sw);
  od_.store(obj::kModesOfOperationDisplay.id, mode_);

  const auto round = [](double x) { return static_cast<std::int64_t>(std::llround(x)); };
  od_.store(obj::kPositionActual.id, round(pos_));
  od_.store({0x6063, 0}, round(pos_));
  od_.store(obj::kPositionDemand.id, round(demand_pos_));
  od_.store({0x60F4, 0}, round(demand_pos_ - pos_));
  od_.store(obj::kVelocityActual.id, round(vel_to_od(vel_)));
  od_.store({0x606B, 0}, round(vel_to_od(demand_vel_)));
  od_.store(obj::kTorqueActual.id, round(torque_));
  od_.store(obj::kVlVelocityDemand.id, round(vl_output_ * vl_scale_));
  od_.store(obj::kVlVelocityActual.id, round(vel_ * vl_scale_));
  std::uint32_t din = 0;
  if (negative_limit_active()) din |= din::kNegativeLimit;
  if (positive_limit_active()) din |= din::kPositiveLimit;
  if (home_switch_active()) din |= din::kHomeSwitch;
  od_.store(obj::kDigitalInputs.id, din);
}

}  // namespace drivegate::cia402::sim
