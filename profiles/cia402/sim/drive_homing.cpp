// DriveModel: homing mode [AKD digest §9; nord §5.5, §6]. Methods 1/2 (limit switch, then the next
// index pulse beyond it), 17/18 (limit switch edge), 33/34 (next index pulse), 35/37 (current
// position). Each limit-switch method searches the switch at 6099h:1, backs off it at 6099h:2 and
// ends where its signal was seen, at position = home offset (607Ch).
#include <cmath>

#include "profiles/cia402/sim/drive_model.hpp"
#include "profiles/cia402/sim/motion_profile.hpp"

namespace drivegate::cia402::sim {
namespace {
constexpr std::uint16_t kCwBit4 = 0x0010;  // homing operation start
constexpr std::uint16_t kCwHalt = 0x0100;

constexpr bool needs_negative_limit(std::int8_t m) noexcept { return m == 1 || m == 17; }
constexpr bool needs_positive_limit(std::int8_t m) noexcept { return m == 2 || m == 18; }
constexpr bool uses_index_after_switch(std::int8_t m) noexcept { return m == 1 || m == 2; }
}  // namespace

void DriveModel::homing_fail() noexcept { homing_ = HomingPhase::Error; }

void DriveModel::start_homing() noexcept {
  homing_method_ = static_cast<std::int8_t>(od(obj::kHomingMethod));
  homing_prev_position_ = physical(pos_);
  const std::int8_t m = homing_method_;
  bool supported = false;
  for (const std::int8_t s : config_.homing_methods) supported = supported || s == m;
  if (!supported) {
    homing_fail();
    return;
  }
  if (needs_negative_limit(m) || needs_positive_limit(m)) {
    const bool negative = needs_negative_limit(m);
    // A method whose switch the machine does not have cannot succeed.
    if (!(negative ? config_.negative_limit_position : config_.positive_limit_position)) {
      homing_fail();
      return;
    }
    const bool on_switch = negative ? negative_limit_active() : positive_limit_active();
    homing_dir_ = (negative == on_switch) ? 1.0 : -1.0;  // off the switch if on it, else towards it
    homing_ = on_switch ? HomingPhase::BackOff : HomingPhase::Search;
    return;
  }
  switch (m) {
    case 33: homing_dir_ = -1.0; homing_ = HomingPhase::Index; return;
    case 34: homing_dir_ = 1.0; homing_ = HomingPhase::Index; return;
    case 35:
    case 37:
      homing_event(physical(pos_));
      demand_pos_ = pos_;
      homing_ = HomingPhase::Attained;
      return;
    default: homing_fail(); return;
  }
}

void DriveModel::homing_event(double physical_home) noexcept {
  // The home point becomes position 607Ch; the reported coordinates shift, the motor does not.
  const double delta = static_cast<double>(od(obj::kHomeOffset)) - (physical_home + coord_offset_);
  coord_offset_ += delta;
  pos_ += delta;
  demand_pos_ += delta;
  pp_last_target_ = pos_;
  homing_ = HomingPhase::MoveToHome;
}

void DriveModel::run_homing(std::uint16_t cw, double dt) noexcept {
  const bool bit4 = (cw & kCwBit4) != 0;
  const bool halt = (cw & kCwHalt) != 0;
  const bool running = homing_ == HomingPhase::Search || homing_ == HomingPhase::BackOff ||
                       homing_ == HomingPhase::Index || homing_ == HomingPhase::MoveToHome;
  // Bit 4 1->0 or a halt interrupts homing [AKD digest §9.3]; a rising edge (re)starts it.
  if (running && (!bit4 || halt)) {
    homing_ = HomingPhase::Interrupted;
  } else if (!running && bit4 && (prev_cw_ & kCwBit4) == 0 && !halt) {
    start_homing();
  }
  const double acc = vel_from_od(od(obj::kHomingAcceleration));
  const double fast = vel_from_od(od(obj::kHomingSpeedSwitch));
  const double slow = vel_from_od(od(obj::kHomingSpeedZero));
  const double here = physical(pos_);
  const double prev = homing_prev_position_;
  homing_prev_position_ = here;

  // A limit switch ahead that is not the signal being looked for ends the search in an error.
  const bool moving = homing_ == HomingPhase::Search || homing_ == HomingPhase::BackOff || homing_ == HomingPhase::Index;
  if (moving) {
    const bool neg_signal = needs_negative_limit(homing_method_) && homing_ != HomingPhase::Index;
    const bool pos_signal = needs_positive_limit(homing_method_) && homing_ != HomingPhase::Index;
    if ((homing_dir_ < 0 && negative_limit_active() && !neg_signal) ||
        (homing_dir_ > 0 && positive_limit_active() && !pos_signal)) {
      homing_fail();
    }
  }

  switch (homing_) {
    case HomingPhase::Idle:
    case HomingPhase::Interrupted:
    case HomingPhase::Error:
      stop_ramp(acc, dt);
      bits_.target_reached = standstill();
      bits_.bit13 = homing_ == HomingPhase::Error;
      return;
    case HomingPhase::Attained:
      hold();
      bits_.bit12 = true;
      bits_.target_reached =
          std::abs(static_cast<double>(od(obj::kHomeOffset)) - pos_) <= static_cast<double>(od(obj::kPositionWindow));
      return;
    case HomingPhase::Search: {
      const bool hit = needs_negative_limit(homing_method_) ? negative_limit_active() : positive_limit_active();
      if (hit) {
        homing_dir_ = -homing_dir_;
        homing_ = HomingPhase::BackOff;
      }
      break;
    }
    case HomingPhase::BackOff: {
      const bool on = needs_negative_limit(homing_method_) ? negative_limit_active() : positive_limit_active();
      if (!on) {
        if (uses_index_after_switch(homing_method_)) {
          homing_ = HomingPhase::Index;
          homing_prev_position_ = here;
        } else {
          homing_event(here);  // the switch edge
        }
      }
      break;
    }
    case HomingPhase::Index: {
      const double rev = config_.position_units_per_rev;
      const double k_prev = std::floor((prev - config_.index_pulse_offset) / rev);
      const double k_here = std::floor((here - config_.index_pulse_offset) / rev);
      if (k_prev != k_here) {
        // Moving up the crossed pulse is the upper boundary of prev's revolution, moving down its lower one.
        const double k = homing_dir_ > 0 ? k_here : k_prev;
        homing_event(config_.index_pulse_offset + k * rev);
      }
      break;
    }
    case HomingPhase::MoveToHome:
      break;
  }

  control_ = Control::Position;
  if (homing_ == HomingPhase::MoveToHome) {
    if (trapezoid_step(demand_pos_, demand_vel_, static_cast<double>(od(obj::kHomeOffset)), slow, acc, acc, dt)) {
      homing_ = HomingPhase::Attained;
      bits_.bit12 = true;
    }
    return;
  }
  if (homing_ == HomingPhase::Error) {
    stop_ramp(acc, dt);
    bits_.bit13 = true;
    return;
  }
  const double speed = homing_ == HomingPhase::Search ? fast : slow;
  demand_vel_ = ramp_velocity(demand_vel_, homing_dir_ * speed, acc, acc, dt);
  demand_pos_ += demand_vel_ * dt;
}

}  // namespace drivegate::cia402::sim
