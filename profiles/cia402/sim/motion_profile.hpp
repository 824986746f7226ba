#pragma once
// Set-point generators the drive model runs on its demand values: velocity ramps and an online
// trapezoidal point-to-point profile, and the servo loops the motor follows them with. Pure
// functions of the state they are given, so every mode (and a stop from any of them) continues
// smoothly from wherever the demand is. The simulated PROFIdrive drive uses them too.
namespace drivegate::cia402::sim {

// Moves v towards target: with `acc` while the speed grows, with `dec` while it shrinks (rates
// per second, >= 0). A rate <= 0 jumps straight to the target.
double ramp_velocity(double v, double target, double acc, double dec, double dt) noexcept;

// Moves x towards target by at most rate * dt (torque slope); rate <= 0 jumps.
double ramp_value(double x, double target, double rate, double dt) noexcept;

// One step of a trapezoidal move of (p, v) to `target`, cruising at most at vmax. Decelerates on
// the curve v = sqrt(2 * dec * distance) so it lands on the target; a target closer than the
// stopping distance is overshot and approached again. Returns true once p == target and v == 0.
bool trapezoid_step(double& p, double& v, double target, double vmax, double acc, double dec, double dt) noexcept;

// The servo loops of the simulated drives: the velocity loop is a first-order lag of time constant
// tau (> 0); under position control a proportional position loop of gain 1/(4 tau) adds to the
// demand velocity, which makes the pair critically damped. servo_command is the velocity command,
// clamped to +-vmax; follow_velocity the motor speed v after dt.
double servo_command(double demand_pos, double demand_vel, double pos, bool position_loop, double tau,
                     double vmax) noexcept;
double follow_velocity(double v, double command, double tau, double dt) noexcept;

}  // namespace drivegate::cia402::sim
