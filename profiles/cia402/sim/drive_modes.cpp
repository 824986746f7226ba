// DriveModel: the operating modes pp, vl, pv, tq, ip, csp, csv and cst (homing has its own file).
#include <algorithm>
#include <cmath>

#include "profiles/cia402/sim/drive_model.hpp"
#include "profiles/cia402/sim/motion_profile.hpp"

namespace drivegate::cia402::sim {
namespace {
constexpr std::uint16_t kCwBit4 = 0x0010;  // pp new set-point, ip enable, vl rfg enable
constexpr std::uint16_t kCwBit5 = 0x0020;  // pp change set immediately, vl rfg unlock
constexpr std::uint16_t kCwBit6 = 0x0040;  // pp relative, vl rfg use reference
constexpr std::uint16_t kCwHalt = 0x0100;
}  // namespace

// ---------------------------------------------------------------------------------------------
// Profile position [AKD digest §10; nord §5.1]

void DriveModel::pp_accept(std::uint16_t cw) noexcept {
  // A new set-point while the acknowledge is still up is ignored (nord §5.1 table 4).
  if (pp_ack_) return;
  Setpoint sp;
  // Relative moves count from the last target taken (CiA 402 default of 60F2h).
  const double base = (cw & kCwBit6) != 0 ? pp_last_target_ : 0.0;
  sp.target = base + static_cast<double>(od(obj::kTargetPosition));
  const auto lo = static_cast<double>(od(obj::kSoftwareLimitMin));
  const auto hi = static_cast<double>(od(obj::kSoftwareLimitMax));
  if (lo < hi) sp.target = std::clamp(sp.target, lo, hi);  // 607Dh: both 0 = off [AKD digest §10.1]
  sp.velocity = std::min({vel_from_od(od(obj::kProfileVelocity)), vel_from_od(od(obj::kMaxProfileVelocity)),
                          max_velocity()});
  sp.acceleration = vel_from_od(od(obj::kProfileAcceleration));
  sp.deceleration = vel_from_od(od(obj::kProfileDeceleration));
  // Bit 5 = 1: the new job replaces the running one at once; 0: it waits until the running job
  // has reached its target (one job deep buffer).
  if (!pp_moving_ || (cw & kCwBit5) != 0) {
    pp_active_ = sp;
    pp_moving_ = true;
    pp_buffered_valid_ = false;
  } else {
    pp_buffered_ = sp;
    pp_buffered_valid_ = true;
  }
  pp_last_target_ = sp.target;
  pp_ack_ = true;
}

void DriveModel::run_pp(std::uint16_t cw, double dt) noexcept {
  // The acknowledge follows bit 4 down, except while a job waits in the buffer: then the drive
  // cannot take another one yet (nord §5.1 table 4).
  if ((cw & kCwBit4) == 0 && !pp_buffered_valid_) pp_ack_ = false;
  if ((cw & kCwBit4) != 0 && (prev_cw_ & kCwBit4) == 0) pp_accept(cw);
  if ((cw & kCwHalt) != 0) {
    stop_ramp(halt_deceleration(), dt);
    bits_.target_reached = standstill();
  } else if (pp_moving_) {
    control_ = Control::Position;
    if (trapezoid_step(demand_pos_, demand_vel_, pp_active_.target, pp_active_.velocity, pp_active_.acceleration,
                       pp_active_.deceleration, dt)) {
      if (pp_buffered_valid_) {
        pp_active_ = pp_buffered_;
        pp_buffered_valid_ = false;
      } else {
        pp_moving_ = false;
      }
    }
  } else {
    hold();
  }
  if ((cw & kCwHalt) == 0) {
    const bool inside = !pp_moving_ && std::abs(pp_active_.target - pos_) <= static_cast<double>(od(obj::kPositionWindow));
    bits_.target_reached = window_reached(inside, od(obj::kPositionWindowTime), dt);
  }
  bits_.bit12 = pp_ack_;
}

// ---------------------------------------------------------------------------------------------
// Velocity modes [AKD digest §5; nord §5.2, §5.3]

void DriveModel::run_pv(double dt) noexcept {
  control_ = Control::Velocity;
  double target = vel_from_od(od(obj::kTargetVelocity));
  const double limit = std::min(vel_from_od(od(obj::kMaxProfileVelocity)), max_velocity());
  if (std::abs(target) > limit) {
    target = std::copysign(limit, target);
    bits_.internal_limit = true;
  }
  demand_vel_ = ramp_velocity(demand_vel_, target, vel_from_od(od(obj::kProfileAcceleration)),
                              vel_from_od(od(obj::kProfileDeceleration)), dt);
  demand_pos_ += demand_vel_ * dt;
  // Velocity reached: actual within 606Dh of the target for 606Eh ms.
  const bool inside = std::abs(vel_to_od(target - vel_)) <= static_cast<double>(od(obj::kVelocityWindow));
  bits_.target_reached = window_reached(inside, od(obj::kVelocityWindowTime), dt);
}

void DriveModel::run_vl(std::uint16_t cw, double dt) noexcept {
  // CiA 402 vl: bit 4 enables the ramp function generator (0: ramp down to 0), bit 5 unlocks it
  // (0: output frozen), bit 6 feeds it the reference (0: reference 0). Running needs 0x007F.
  control_ = Control::Velocity;
  double input = (cw & kCwBit6) != 0 ? static_cast<double>(od(obj::kVlTargetVelocity)) / vl_scale_ : 0.0;
  if (std::abs(input) > max_velocity()) {
    input = std::copysign(max_velocity(), input);
    bits_.internal_limit = true;
  }
  const double acc = vl_rate(obj::kVlAccelerationDeltaSpeed, obj::kVlAccelerationDeltaTime);
  const double dec = vl_rate(obj::kVlDecelerationDeltaSpeed, obj::kVlDecelerationDeltaTime);
  if ((cw & kCwBit4) == 0) {
    vl_output_ = ramp_velocity(vl_output_, 0.0, dec, dec, dt);
  } else if ((cw & kCwBit5) != 0) {
    vl_output_ = ramp_velocity(vl_output_, input, acc, dec, dt);
  }
  demand_vel_ = vl_output_;
  demand_pos_ += demand_vel_ * dt;
}

void DriveModel::run_csv() noexcept {
  control_ = Control::Velocity;
  const double target = vel_from_od(od(obj::kTargetVelocity) + od(obj::kVelocityOffset));
  demand_vel_ = std::clamp(target, -max_velocity(), max_velocity());
  bits_.internal_limit = demand_vel_ != target;
  bits_.bit12 = true;  // following the set-points
}

// ---------------------------------------------------------------------------------------------
// Torque modes [AKD digest §6; nord §5.4]

void DriveModel::run_tq(double dt) noexcept {
  control_ = Control::Torque;
  const auto max = static_cast<double>(od(obj::kMaxTorque));
  const auto wanted = static_cast<double>(od(obj::kTargetTorque));
  const double target = std::clamp(wanted, -max, max);
  bits_.internal_limit = target != wanted;
  torque_demand_ = ramp_value(torque_demand_, target, static_cast<double>(od(obj::kTorqueSlope)), dt);
  bits_.target_reached = torque_demand_ == target;
  demand_pos_ = pos_;
  demand_vel_ = vel_;
}

void DriveModel::run_cst() noexcept {
  control_ = Control::Torque;
  const auto max = static_cast<double>(od(obj::kMaxTorque));
  const auto wanted = static_cast<double>(od(obj::kTargetTorque) + od(obj::kTorqueOffset));
  torque_demand_ = std::clamp(wanted, -max, max);
  bits_.internal_limit = torque_demand_ != wanted;
  bits_.bit12 = true;
  demand_pos_ = pos_;
  demand_vel_ = vel_;
}

// ---------------------------------------------------------------------------------------------
// Cyclic position modes [AKD digest §8, §14 step 17]

void DriveModel::run_ip(std::uint16_t cw, double dt) noexcept {
  // A 60C1h:1 set-point is taken only with bit 4 (enable interpolation) set [AKD digest §8.2]. It
  // is taken as it is each step: the sim bus steps once per interpolation period.
  if ((cw & kCwBit4) == 0) {
    hold();
    return;
  }
  control_ = Control::Position;
  const auto target = static_cast<double>(od(obj::kIpDataRecord));
  demand_vel_ = (target - demand_pos_) / dt;
  demand_pos_ = target;
  bits_.bit12 = true;  // ip mode active
}

void DriveModel::run_csp(double dt) noexcept {
  control_ = Control::Position;
  const auto target = static_cast<double>(od(obj::kTargetPosition));
  demand_vel_ = (target - demand_pos_) / dt + vel_from_od(od(obj::kVelocityOffset));
  demand_pos_ = target;
  bits_.bit12 = true;  // following the set-points
}

}  // namespace drivegate::cia402::sim
