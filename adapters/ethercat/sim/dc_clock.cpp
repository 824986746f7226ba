#include "adapters/ethercat/sim/dc_clock.hpp"

#include <algorithm>
#include <cmath>

namespace drivegate::ethercat::sim {

void DcClock::reset(std::int64_t offset_ns, double drift_ppm) noexcept {
  *this = DcClock{};
  offset_ = offset_ns;
  drift_ = drift_ppm * 1e-6;
}

void DcClock::anchor(std::uint64_t t) const noexcept {
  if (anchored_) return;
  anchored_ = true;
  t0_ = t;
  t_last_ = t;
}

double DcClock::loop_correction(std::uint64_t t) const noexcept {
  const auto dt = static_cast<std::int64_t>(t - t_last_);
  const auto fdt = static_cast<double>(dt);
  double slew = slew_rate_ * fdt;
  if (dt >= 0 && std::fabs(slew) > std::fabs(slew_left_)) slew = slew_left_;  // the slew has ended
  return p_last_ + freq_ * fdt + slew;
}

double DcClock::correction(std::uint64_t t) const noexcept {
  anchor(t);
  return drift_ * static_cast<double>(static_cast<std::int64_t>(t - t0_)) + loop_correction(t);
}

std::uint64_t DcClock::local(std::uint64_t t) const noexcept {
  const double c = std::floor(correction(t));
  return t + static_cast<std::uint64_t>(offset_) + static_cast<std::uint64_t>(static_cast<std::int64_t>(c));
}

double DcClock::fraction(std::uint64_t t) const noexcept {
  const double c = correction(t);
  return c - std::floor(c);
}

void DcClock::advance(std::uint64_t t) noexcept {
  anchor(t);
  if (static_cast<std::int64_t>(t - t_last_) <= 0) return;
  const auto fdt = static_cast<double>(static_cast<std::int64_t>(t - t_last_));
  double slew = slew_rate_ * fdt;
  if (std::fabs(slew) >= std::fabs(slew_left_)) {
    slew = slew_left_;
    slew_rate_ = 0.0;
  }
  p_last_ += freq_ * fdt + slew;
  slew_left_ -= slew;
  t_last_ = t;
}

void DcClock::sample(std::uint64_t t, double error_ns) noexcept {
  advance(t);
  // The error as it would be without anything the loop did: its slope is the frequency difference.
  const double natural = error_ns - loop_correction(t);
  if (!have_window_) {
    have_window_ = true;
    window_t_ = t;
    window_error_ = natural;
  } else if (const auto dt = static_cast<std::int64_t>(t - window_t_); dt >= kWindowNs) {
    const double measured = (natural - window_error_) / static_cast<double>(dt);
    estimate_ = have_estimate_ ? estimate_ + 0.5 * (measured - estimate_) : measured;
    have_estimate_ = true;
    freq_ = -estimate_;
    window_t_ = t;
    window_error_ = natural;
  }
  slew_left_ = -error_ns;
  slew_rate_ = std::clamp(-error_ns / kSlewTauNs, -kMaxSlew, kMaxSlew);
}

void DcClock::reset_loop() noexcept {
  // The clock keeps its phase (the correction so far stays in p_last_); the loop starts over.
  freq_ = 0.0;
  estimate_ = 0.0;
  have_estimate_ = false;
  restart_window();
}

void DcClock::restart_window() noexcept {
  have_window_ = false;
  slew_left_ = 0.0;
  slew_rate_ = 0.0;
}

}  // namespace drivegate::ethercat::sim
