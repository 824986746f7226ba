// DriveModel: what the power stage does in each state, speed mode (application class 1), position
// mode (class 3: program mode, MDI, homing), jog, the motor and following-error monitoring.
#include <algorithm>
#include <cmath>

#include "profiles/cia402/sim/motion_profile.hpp"
#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/scaling.hpp"
#include "profiles/profidrive/sim/drive_model.hpp"

namespace drivegate::profidrive::sim {
namespace {

using cia402::sim::follow_velocity;
using cia402::sim::ramp_velocity;
using cia402::sim::servo_command;
using cia402::sim::trapezoid_step;

constexpr bool has(std::uint16_t word, std::uint16_t bits) noexcept { return (word & bits) == bits; }
constexpr bool rising(std::uint16_t prev, std::uint16_t now, std::uint16_t bit) noexcept {
  return (now & bit) != 0 && (prev & bit) == 0;
}
constexpr std::uint16_t kMdiSelect = 0x8000;  // SATZANW bit 15 [§16.3]
constexpr std::uint16_t kHomeModeCurrentPosition = 0;
constexpr std::uint16_t kHomeModeHomeSwitch = 4;

}  // namespace

double DriveModel::cpr() const noexcept { return counts_per_rev(single_turn_bits_).value_or(65536.0); }

double DriveModel::acc_full_scale() const noexcept {
  return acc_full_scale_from_pnu1008(pnu1008_).value_or(kMdiAccDefaultRpmPerS);
}

std::optional<DriveModel::Task> DriveModel::task_from(std::int32_t position, std::uint32_t velocity, std::uint16_t acc,
                                                      std::uint16_t dec, std::uint16_t control) const noexcept {
  // A task without speed or ramps cannot run: the drive does not acknowledge it [§16.3].
  if (velocity == 0 || acc == 0 || dec == 0) return std::nullopt;
  Task t;
  const double p = static_cast<double>(position) / cpr();
  t.target = (control & 1U) != 0 ? p : demand_pos_ + p;  // MDI_MOD bit 0: absolute [§12.2]
  t.velocity = std::min(rpm_from_mdi_velocity(velocity) / 60.0, config_.max_speed_rps);
  t.acceleration = rpm_per_s_from_mdi_acc(acc, acc_full_scale()) / 60.0;
  t.deceleration = rpm_per_s_from_mdi_acc(dec, acc_full_scale()) / 60.0;
  return t;
}

void DriveModel::ramp_demand(double target_velocity, double acc, double dec, double dt) noexcept {
  // A speed drive ramps its speed; in position mode the position loop follows the ramp and holds.
  control_ = mode_ == OperatingMode::Speed ? Control::Velocity : Control::Position;
  demand_vel_ = ramp_velocity(demand_vel_, target_velocity, acc, dec, dt);
  demand_pos_ += demand_vel_ * dt;
}

void DriveModel::run_motion(std::uint16_t c, double dt) noexcept {
  // Coming from no control, the loops take over from where the motor is.
  if (control_ == Control::Coast) {
    demand_pos_ = pos_;
    demand_vel_ = vel_;
  }
  const double demand_from = demand_pos_;
  const Control before = control_;
  control_ = Control::Coast;
  const double quick = config_.quick_stop_dec_rpm_per_s / 60.0;
  switch (state_) {
    case State::S4Operation:
      if (run_jog(c, dt)) break;
      if (mode_ == OperatingMode::Speed) run_speed_mode(c, dt);
      else run_position_mode(c, dt);
      break;
    case State::S5RampStop: ramp_demand(0.0, 0.0, config_.speed_dec_rpm_per_s / 60.0, dt); break;
    case State::S5QuickStop: ramp_demand(0.0, 0.0, quick, dt); break;
    case State::Fault:
      // Fault reaction [sim]: brake on the quick stop ramp, then the power stage goes off.
      if (before != Control::Coast && !standstill()) ramp_demand(0.0, 0.0, quick, dt);
      break;
    case State::S1SwitchingOnInhibited:
    case State::S2ReadyForSwitchingOn:
    case State::S3SwitchedOn:
      break;  // pulses off: the motor coasts
  }
  motor_update(dt, demand_from);
}

void DriveModel::run_speed_mode(std::uint16_t c, double dt) noexcept {
  // STW1 bits 4..6 [§8.2]: bit 4 low sets the ramp-function generator's output to 0 (stop on the
  // quick stop ramp), bit 5 low freezes it, bit 6 low makes the setpoint 0. 2^15 = 12000 rpm [§17.1].
  control_ = Control::Velocity;
  const double target = has(c, stw1::kEnableSetpoint)
                            ? std::clamp(rpm_from_speed_word(sp_.nsoll_a) / 60.0, -config_.max_speed_rps, config_.max_speed_rps)
                            : 0.0;
  if (!has(c, stw1::kEnableRampGenerator)) {
    const double quick = config_.quick_stop_dec_rpm_per_s / 60.0;
    demand_vel_ = ramp_velocity(demand_vel_, 0.0, quick, quick, dt);
  } else if (has(c, stw1::kUnfreezeRampGenerator)) {
    demand_vel_ = ramp_velocity(demand_vel_, target, config_.speed_acc_rpm_per_s / 60.0, config_.speed_dec_rpm_per_s / 60.0, dt);
  }
  speed_reached_ = demand_vel_ == target && std::abs(vel_ - target) * 60.0 <= config_.speed_reached_window_rpm;
}

bool DriveModel::run_jog(std::uint16_t c, double dt) noexcept {
  // Jog 1/2 (bits 8/9) in both classes: from standstill with bits 4..6 low, to PNU 1004/1005 on the
  // ramps PNU 1006/1007, back to standstill when the bit drops [§8.2, §16.5]. Real-time jog (bits
  // 12/13, position mode) takes MDI_VELOCITY/ACC/DEC from the telegram [§8.3, §16.5].
  const bool run_bits = (c & (stw1::kEnableRampGenerator | stw1::kUnfreezeRampGenerator | stw1::kEnableSetpoint)) != 0;
  const bool jog1 = has(c, stw1::kJog1);
  const bool jog2 = has(c, stw1::kJog2);
  const bool rt = mode_ == OperatingMode::Position && has(c, stw1::kRealTimeJog);
  const bool busy = task_.has_value() || homing_ == Homing::Search || homing_ == Homing::MoveToDist;
  if (!jogging_) {
    if (!(jog1 || jog2 || rt) || (run_bits && !rt) || busy || !standstill()) return false;
    jogging_ = true;
  }
  double target = 0.0;
  double acc = jog_acc_ / 60.0;
  double dec = jog_dec_ / 60.0;
  if (rt) {
    target = std::min(rpm_from_mdi_velocity(sp_.mdi_velocity) / 60.0, config_.max_speed_rps);
    if (has(c, stw1::kRealTimeJogCcw)) target = -target;
    acc = rpm_per_s_from_mdi_acc(sp_.mdi_acc, acc_full_scale()) / 60.0;
    dec = rpm_per_s_from_mdi_acc(sp_.mdi_dec, acc_full_scale()) / 60.0;
  } else if (!run_bits && jog1 != jog2) {  // both bits at once: no jog [sim]
    target = std::clamp(rpm_from_speed_word(jog_[jog1 ? 0 : 1]) / 60.0, -config_.max_speed_rps, config_.max_speed_rps);
  }
  ramp_demand(target, acc, dec, dt);
  if (target == 0.0 && demand_vel_ == 0.0) jogging_ = false;
  return true;
}

void DriveModel::run_position_mode(std::uint16_t c, double dt) noexcept {
  run_homing(c, dt);
  if (homing_ == Homing::Search || homing_ == Homing::MoveToDist) return;

  // Traversing tasks [§16.2, §16.3]: the rising edge of bit 6 with bit 4 set starts a stored task
  // (program mode) or loads the MDI values (SATZANW bit 15); ZSW1 bit 12 acknowledges it and
  // follows bit 6 back to 0 (a level handshake [§25.9]).
  if (!has(c, stw1::kActivateTask)) task_ack_ = false;
  if (rising(prev_stw1_, c, stw1::kActivateTask) && has(c, stw1::kDoNotRejectTask)) start_task(c);
  if (task_ && !has(c, stw1::kDoNotRejectTask)) task_.reset();  // bit 4 low rejects the running task

  if (!task_) {
    // No task: stop what is still moving on the quick stop ramp (an aborted task), then hold.
    const double quick = config_.quick_stop_dec_rpm_per_s / 60.0;
    ramp_demand(0.0, 0.0, quick, dt);
    return;
  }
  control_ = Control::Position;
  if (!has(c, stw1::kNoIntermediateStop)) {
    // Intermediate stop: brake on the task's ramp and wait; bit 5 back to 1 goes on [§16.2].
    ramp_demand(0.0, 0.0, task_->deceleration, dt);
    return;
  }
  if (trapezoid_step(demand_pos_, demand_vel_, task_->target, task_->velocity, task_->acceleration,
                     task_->deceleration, dt)) {
    task_.reset();
    target_reached_ = true;
  }
}

void DriveModel::start_task(std::uint16_t c) noexcept {
  // Preconditions [§16.2, §16.3]: S4 (the caller), position mode, homed, no homing or jog running.
  if (!homed_ || jogging_ || has(c, stw1::kStartHoming)) return;
  std::optional<Task> t;
  if ((sp_.satzanw & kMdiSelect) != 0) {
    t = task_from(sp_.mdi_tarpos, sp_.mdi_velocity, sp_.mdi_acc, sp_.mdi_dec, sp_.mdi_mod);
  } else if (sp_.satzanw < kMotionTasks) {
    const MotionTask& m = tasks_[sp_.satzanw];
    t = task_from(m.position, m.velocity, m.acceleration, m.deceleration, m.control);
  }
  if (!t) return;  // ZSW1 bit 12 stays 0: the drive cannot execute the task [§16.3]
  task_ = t;
  task_target_ = t->target;
  task_ack_ = true;
  target_reached_ = false;
  aktsatz_ = sp_.satzanw;
}

void DriveModel::run_homing(std::uint16_t c, double dt) noexcept {
  // STW1 bit 11 [§16.4]: the rising edge starts homing (not while a task runs), clearing it aborts
  // and leaves the axis unhomed; done when ZSW1 bits 10, 11 and 13 are all 1.
  const bool bit11 = has(c, stw1::kStartHoming);
  const bool running = homing_ == Homing::Search || homing_ == Homing::MoveToDist;
  if (!bit11) {
    if (running) homed_ = false;
    homing_ = Homing::Idle;
    return;
  }
  if (rising(prev_stw1_, c, stw1::kStartHoming) && !task_ && !jogging_) {
    // HOME.MODE and HOME.DIST come from telegram 353/352 when it carries them, else from the PNUs.
    const std::uint16_t mode = layout_.carries(Signal::HomeMode) ? sp_.home_mode : home_mode_;
    if (layout_.carries(Signal::HomeDist)) home_dist_ = sp_.home_dist;
    homed_ = false;
    target_reached_ = false;
    const bool supported = mode == kHomeModeCurrentPosition || (mode == kHomeModeHomeSwitch && config_.home_switch_rev);
    homing_ = supported ? Homing::Search : Homing::Failed;
    home_mode_ = mode;
  }
  if (homing_ == Homing::Search) {
    bool found = home_mode_ == kHomeModeCurrentPosition;
    if (!found) {
      ramp_demand(config_.homing_speed_rps, config_.homing_acc_rps2, config_.homing_acc_rps2, dt);
      found = pos_ - home_offset_ >= *config_.home_switch_rev;
    }
    if (found) {
      // The reference point becomes HOME.P; the drive then moves HOME.DIST from it [§16.4].
      const double shift = static_cast<double>(home_p_) / cpr() - pos_;
      pos_ += shift;
      demand_pos_ += shift;
      home_offset_ += shift;
      homing_target_ = static_cast<double>(home_p_) / cpr() + static_cast<double>(home_dist_) / cpr();
      homing_ = Homing::MoveToDist;
    }
    return;
  }
  if (homing_ == Homing::MoveToDist) {
    control_ = Control::Position;
    // Done once the motor has settled: bits 10, 11 and 13 then come together [§16.4].
    if (trapezoid_step(demand_pos_, demand_vel_, homing_target_, config_.homing_speed_rps, config_.homing_acc_rps2,
                       config_.homing_acc_rps2, dt) &&
        standstill()) {
      homing_ = Homing::Done;
      homed_ = true;
    }
  }
}

void DriveModel::motor_update(double dt, double demand_from) noexcept {
  // The drive closes its loops far faster than the telegram arrives (the AKD's update time on
  // PROFINET is 16 ms or more [§2]); the motor is integrated in steps of at most a quarter of the
  // velocity loop's time constant, with the position demand moving linearly from `demand_from` to
  // this update's demand, so the position loop settles whatever `dt` is. (One step of 16 ms on a
  // 2 ms loop overshoots and leaves the motor oscillating about its target, never at standstill.)
  const double tau = std::max(config_.velocity_time_constant_s, 1e-6);
  const int steps = static_cast<int>(std::clamp(std::ceil(dt / (tau / 4.0)), 1.0, static_cast<double>(kMaxMotorSteps)));
  const double h = dt / steps;
  const double v_start = vel_;
  v_cmd_ = 0.0;
  for (int k = 1; k <= steps; ++k) {
    const double v_old = vel_;
    if (control_ == Control::Coast) {
      vel_ *= std::exp(-config_.friction_per_rps * config_.acceleration_at_peak_current_rps2 * h);
    } else {
      const double demand = demand_from + (demand_pos_ - demand_from) * k / steps;
      v_cmd_ = servo_command(demand, demand_vel_, pos_, control_ == Control::Position, tau, config_.max_speed_rps);
      // A speed loop without position loop settles below its setpoint under load (speed_droop).
      const double droop = control_ == Control::Velocity ? 1.0 - config_.speed_droop : 1.0;
      vel_ = follow_velocity(vel_, v_cmd_ * droop, tau, h);
    }
    if (blocked_) vel_ = 0.0;
    pos_ += 0.5 * (v_old + vel_) * h;
  }
  acc_ = (vel_ - v_start) / dt;
  if (control_ == Control::Velocity) demand_pos_ = pos_;  // no position loop: nothing to wind up
}

void DriveModel::check_following_error() noexcept {
  // F439 when the position loop's error passes PL.ERRFTHRESH in S4 [§9.3, §16.2]; 0 switches it off.
  if (state_ != State::S4Operation || control_ != Control::Position || pl_errfthresh_ == 0) return;
  if (std::abs(demand_pos_ - pos_) * cpr() > static_cast<double>(pl_errfthresh_)) raise_fault(fault_number::kFollowingError);
}

}  // namespace drivegate::profidrive::sim
