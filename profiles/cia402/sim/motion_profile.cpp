#include "profiles/cia402/sim/motion_profile.hpp"

#include <algorithm>
#include <cmath>

namespace drivegate::cia402::sim {

double ramp_velocity(double v, double target, double acc, double dec, double dt) noexcept {
  const bool speeding_up = std::abs(target) > std::abs(v) && v * target >= 0.0;
  const double rate = speeding_up ? acc : dec;
  if (rate <= 0.0) return target;
  const double step = rate * dt;
  if (std::abs(target - v) <= step) return target;
  return target > v ? v + step : v - step;
}

double ramp_value(double x, double target, double rate, double dt) noexcept {
  if (rate <= 0.0) return target;
  const double step = rate * dt;
  if (std::abs(target - x) <= step) return target;
  return target > x ? x + step : x - step;
}

bool trapezoid_step(double& p, double& v, double target, double vmax, double acc, double dec, double dt) noexcept {
  const double d = target - p;
  const double dist = std::abs(d);
  if (dist < 1e-9 && std::abs(v) < 1e-9) {
    p = target;
    v = 0.0;
    return true;
  }
  const double dir = d >= 0.0 ? 1.0 : -1.0;
  const double vd = v * dir;  // speed towards the target (negative: moving away)
  const double vstop = std::sqrt(2.0 * dec * dist);
  double vd_new = 0.0;
  if (vd < 0.0) {
    vd_new = vd + dec * dt;  // moving away: brake first
  } else if (vd > vstop + dec * dt) {
    vd_new = vd - dec * dt;  // too close to stop in time: brake and overshoot
  } else {
    vd_new = vd > vmax ? std::max(vd - dec * dt, vmax) : std::min(vd + acc * dt, vmax);
    vd_new = std::min(vd_new, vstop);
    // The last step of the braking curve would pass the target: land on it.
    if (vd_new * dt >= dist && vd_new <= 2.0 * dec * dt + 1e-9) {
      p = target;
      v = 0.0;
      return true;
    }
  }
  v = dir * vd_new;
  p += v * dt;
  return false;
}

double servo_command(double demand_pos, double demand_vel, double pos, bool position_loop, double tau,
                     double vmax) noexcept {
  const double kp = position_loop ? 1.0 / (4.0 * tau) : 0.0;
  return std::clamp(demand_vel + kp * (demand_pos - pos), -vmax, vmax);
}

double follow_velocity(double v, double command, double tau, double dt) noexcept {
  return v + (command - v) * (1.0 - std::exp(-dt / tau));
}

}  // namespace drivegate::cia402::sim
