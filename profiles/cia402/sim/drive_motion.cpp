// DriveModel: what the power stage does in each state, stop ramps, limit switches, the motor/load
// model and following-error monitoring.
#include <algorithm>
#include <cmath>

#include "profiles/cia402/sim/drive_model.hpp"
#include "profiles/cia402/sim/motion_profile.hpp"

namespace drivegate::cia402::sim {
namespace {
constexpr std::uint16_t kCwHalt = 0x0100;

constexpr bool is_position_mode(std::int8_t m) noexcept {
  return m == op_mode::kProfilePosition || m == op_mode::kHoming || m == op_mode::kInterpolatedPosition ||
         m == op_mode::kCyclicPosition;
}
}  // namespace

void DriveModel::change_mode(std::int8_t mode) noexcept {
  mode_ = mode;
  // The new mode starts from where the motor is.
  demand_pos_ = pos_;
  demand_vel_ = vel_;
  torque_demand_ = torque_;
  vl_output_ = vel_;
  pp_moving_ = false;
  pp_buffered_valid_ = false;
  pp_ack_ = false;
  pp_active_ = Setpoint{pos_, 0, 0, 0};
  pp_last_target_ = pos_;
  homing_ = HomingPhase::Idle;
  window_time_ = 0;
}

double DriveModel::vl_rate(ObjectDef delta_speed, ObjectDef delta_time) const noexcept {
  const std::int64_t t = od(delta_time);
  if (t <= 0) return 0.0;  // no ramp
  return static_cast<double>(od(delta_speed)) / vl_scale_ / static_cast<double>(t);
}

double DriveModel::mode_deceleration() const noexcept {
  if (mode_ == op_mode::kVelocity) return vl_rate(obj::kVlDecelerationDeltaSpeed, obj::kVlDecelerationDeltaTime);
  if (mode_ == op_mode::kHoming) return vel_from_od(od(obj::kHomingAcceleration));  // 609Ah: accel and decel
  return vel_from_od(od(obj::kProfileDeceleration));
}

double DriveModel::halt_deceleration() const noexcept {
  // 605Dh: 1 = slow down ramp, 2 = quick stop ramp, 3 (current limit) approximated by the quick stop ramp.
  return od(obj::kHaltOption) == 1 ? mode_deceleration() : vel_from_od(od(obj::kQuickStopDeceleration));
}

double DriveModel::quick_stop_deceleration(std::int64_t option) const noexcept {
  // 605Ah [AKD digest §3.5]: 1/5 deceleration ramp, 2/6 quick stop ramp.
  return (option == 1 || option == 5) ? mode_deceleration() : vel_from_od(od(obj::kQuickStopDeceleration));
}

void DriveModel::stop_ramp(double dec, double dt) noexcept {
  control_ = Control::Position;
  demand_vel_ = ramp_velocity(demand_vel_, 0.0, dec, dec, dt);
  demand_pos_ += demand_vel_ * dt;
}

void DriveModel::hold() noexcept {
  control_ = Control::Position;
  demand_vel_ = 0.0;
}

bool DriveModel::window_reached(bool inside, std::int64_t time_ms, double dt) noexcept {
  window_time_ = inside ? window_time_ + dt : 0.0;
  return inside && window_time_ * 1000.0 >= static_cast<double>(time_ms);
}

void DriveModel::run_motion(std::uint16_t cw, double dt) noexcept {
  bits_ = ModeBits{};
  // Coming from no control or torque control: position/velocity control takes over from the motor.
  if (prev_control_ == Control::Coast || prev_control_ == Control::Torque) {
    demand_pos_ = pos_;
    demand_vel_ = vel_;
  }
  control_ = Control::Coast;
  switch (state_) {
    case DriveState::Unknown:  // never entered by the drive
    case DriveState::NotReadyToSwitchOn:
    case DriveState::SwitchOnDisabled:
    case DriveState::ReadyToSwitchOn:
    case DriveState::Fault:
      break;  // no torque
    case DriveState::SwitchedOn:
      // Power stage on in Switched on (AKD digest §15 quirk 1): the drive holds where the
      // disable-operation ramp left it.
      if (demand_vel_ != 0.0) {
        stop_ramp(mode_deceleration(), dt);
      } else {
        hold();
      }
      break;
    case DriveState::OperationEnabled:
      if (oe_stop_ != OeStop::None) {
        stop_ramp(mode_deceleration(), dt);
      } else {
        run_mode(cw, dt);
      }
      break;
    case DriveState::QuickStopActive:
      stop_ramp(quick_stop_deceleration(od(obj::kQuickStopOption)), dt);
      bits_.target_reached = standstill();
      break;
    case DriveState::FaultReactionActive: {
      const std::int64_t option = od(obj::kFaultReactionOption);
      if (option == 1) stop_ramp(mode_deceleration(), dt);
      if (option == 2) stop_ramp(vel_from_od(od(obj::kQuickStopDeceleration)), dt);
      break;  // 0: the power stage is switched off and the motor coasts
    }
  }
  apply_limit_switches();
  motor_update(dt);
  check_following_error(dt);
  prev_control_ = control_;
}

void DriveModel::run_mode(std::uint16_t cw, double dt) noexcept {
  const bool halt = (cw & kCwHalt) != 0;
  switch (mode_) {
    case op_mode::kProfilePosition: run_pp(cw, dt); return;  // pp keeps its set-points through a halt
    case op_mode::kHoming: run_homing(cw, dt); return;        // halt interrupts homing
    default: break;
  }
  if (halt) {  // CW bit 8: stop and hold in every mode, set-points kept [AKD digest §3.3]
    stop_ramp(halt_deceleration(), dt);
    bits_.target_reached = standstill();
    return;
  }
  switch (mode_) {
    case op_mode::kVelocity: run_vl(cw, dt); break;
    case op_mode::kProfileVelocity: run_pv(dt); break;
    case op_mode::kProfileTorque: run_tq(dt); break;
    case op_mode::kInterpolatedPosition: run_ip(cw, dt); break;
    case op_mode::kCyclicPosition: run_csp(dt); break;
    case op_mode::kCyclicVelocity: run_csv(); break;
    case op_mode::kCyclicTorque: run_cst(); break;
    default: hold(); break;  // no mode selected: hold position
  }
}

void DriveModel::apply_limit_switches() noexcept {
  // In Operation enabled a limit switch stops motion towards it at once and reports an internal
  // limit; motion away from it stays possible. Homing uses the switches as its signals instead.
  limit_blocks_positive_ = false;
  limit_blocks_negative_ = false;
  if (state_ != DriveState::OperationEnabled || mode_ == op_mode::kHoming) return;
  limit_blocks_positive_ = positive_limit_active();
  limit_blocks_negative_ = negative_limit_active();
  if (limit_blocks_positive_) {
    bits_.internal_limit = true;
    demand_vel_ = std::min(demand_vel_, 0.0);
    demand_pos_ = std::min(demand_pos_, pos_);
  }
  if (limit_blocks_negative_) {
    bits_.internal_limit = true;
    demand_vel_ = std::max(demand_vel_, 0.0);
    demand_pos_ = std::max(demand_pos_, pos_);
  }
}

void DriveModel::motor_update(double dt) noexcept {
  const double vmax = max_velocity();
  const double tau = std::max(config_.velocity_time_constant_s, 1e-6);
  const double accel_per_rated = config_.torque_acceleration_rps2 * config_.position_units_per_rev;
  const double friction = config_.viscous_friction * config_.torque_acceleration_rps2;  // 1/s
  const double max_torque = static_cast<double>(od(obj::kMaxTorque));
  const double v_old = vel_;
  double v_cmd = 0.0;
  switch (control_) {
    case Control::Coast:
      vel_ *= std::exp(-friction * dt);
      break;
    case Control::Position:
    case Control::Velocity:
      v_cmd = servo_command(demand_pos_, demand_vel_, pos_, control_ == Control::Position, tau, vmax);
      vel_ = follow_velocity(vel_, v_cmd, tau, dt);
      break;
    case Control::Torque:
      vel_ = std::clamp(vel_ + (torque_demand_ / 1000.0 * accel_per_rated - friction * vel_) * dt, -vmax, vmax);
      break;
  }
  if (limit_blocks_positive_) vel_ = std::min(vel_, 0.0);
  if (limit_blocks_negative_) vel_ = std::max(vel_, 0.0);
  if (blocked_) vel_ = 0.0;
  pos_ += 0.5 * (v_old + vel_) * dt;

  switch (control_) {
    case Control::Coast: torque_ = 0.0; break;
    case Control::Torque: torque_ = torque_demand_; break;
    case Control::Position:
    case Control::Velocity:
      if (blocked_ && v_cmd != 0.0) {
        torque_ = v_cmd > 0.0 ? max_torque : -max_torque;  // stalled: the current loop saturates
      } else {
        torque_ = std::clamp(((vel_ - v_old) / dt + friction * vel_) / accel_per_rated * 1000.0, -max_torque,
                             max_torque);
      }
      break;
  }
  if (control_ == Control::Velocity) demand_pos_ = pos_;  // no position loop: nothing to wind up
}

void DriveModel::check_following_error(double dt) noexcept {
  const std::int64_t window = od(obj::kFollowingErrorWindow);
  // 0 (AKD digest §7) and FFFFFFFFh (CiA 402) both switch monitoring off.
  const bool monitored = state_ == DriveState::OperationEnabled && control_ == Control::Position &&
                         is_position_mode(mode_) && window != 0 && window != 0xFFFFFFFFLL;
  if (!monitored || std::abs(demand_pos_ - pos_) <= static_cast<double>(window)) {
    following_error_ = false;
    following_error_time_ = 0.0;
    return;
  }
  following_error_ = true;
  following_error_time_ += dt;
  if (mode_ != op_mode::kHoming) bits_.bit13 = true;
  if (following_error_time_ * 1000.0 > static_cast<double>(od(obj::kFollowingErrorTimeout))) {
    raise_fault(fault_code::kFollowingError);
  }
}

}  // namespace drivegate::cia402::sim
