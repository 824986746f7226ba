#pragma once
// The local clock of a simulated ESC's distributed clock unit and its time control loop
// [ETG.1000.4 §6 DC registers 0900h-0935h; the loop itself is the ESC's business, ETG.1000.4 only
// says that a written system time is compared with the local copy (plus 0928h) and the clock is
// made to follow].
//
// The oscillator: local(t) = t + offset + drift·(t - t0) + C(t), with t the line's time (ns, the
// SimLine's time line), `offset` the power-on phase, `drift` in ppm (a crystal is typically within
// ±100 ppm), t0 the first time the clock was asked (its power-on), and C the correction the control
// loop has applied so far.
//
// The control loop ("a simple PLL", a model, not an ESC's speed counter): every system time sample
// (the error e = own system time - received time - 0928h, in ns, exact to a fraction) does two
// things:
//   - frequency: from samples at least kWindowNs apart, the slope of the error without the loop's
//     own correction is the frequency difference to the reference; the estimate follows it by half
//     each window, and the clock runs at -estimate from then on;
//   - phase: the clock slews by -e at e/kSlewTauNs per ns (at most kMaxSlew), then stops, so a
//     clock that gets no more samples keeps its frequency and does not run away.
// A write to 0930h (speed counter start) resets the loop [ETG.1000.4 §6: it restarts the DC control
// loop's filters]; a write to the offset or delay restarts the frequency window and drops the slew
// (the error jumps with it).
//
// No allocation; doubles only for the sub-nanosecond part (values stay small: the correction, not
// the time).
#include <cstdint>

namespace drivegate::ethercat::sim {

class DcClock {
 public:
  static constexpr std::int64_t kWindowNs = 1'000'000;  // frequency measured over >= 1 ms
  static constexpr double kSlewTauNs = 1'000'000.0;      // phase error removed within about 1 ms
  static constexpr double kMaxSlew = 500e-6;             // at most 500 ppm of slewing

  // Power-on: `offset_ns` local minus line time at t0, `drift_ppm` the oscillator's error.
  void reset(std::int64_t offset_ns, double drift_ppm) noexcept;

  // Local time at line time t (ns, rounded down), and the fraction of a ns beyond it.
  [[nodiscard]] std::uint64_t local(std::uint64_t t) const noexcept;
  [[nodiscard]] double fraction(std::uint64_t t) const noexcept;

  // A system time sample at line time t: `error_ns` = own system time - (received + delay).
  void sample(std::uint64_t t, double error_ns) noexcept;
  // 0930h written: the loop forgets its frequency estimate, slew and window.
  void reset_loop() noexcept;
  // 0920h or 0928h written: the error jumps; the frequency window restarts and the slew stops.
  void restart_window() noexcept;
  // Time moves on (the PDI cycle): fixes the correction up to t.
  void advance(std::uint64_t t) noexcept;

  // The frequency correction the loop applies now, in ppm (minus the estimated drift to the
  // reference).
  [[nodiscard]] double frequency_ppm() const noexcept { return freq_ * 1e6; }

 private:
  void anchor(std::uint64_t t) const noexcept;
  // Everything added to t + offset at line time t (drift and loop correction), in ns.
  [[nodiscard]] double correction(std::uint64_t t) const noexcept;
  [[nodiscard]] double loop_correction(std::uint64_t t) const noexcept;

  std::int64_t offset_ = 0;
  double drift_ = 0.0;  // dimensionless (ppm · 1e-6)
  // t0: set at the first use after reset() (mutable: a const read may be the first use).
  mutable bool anchored_ = false;
  mutable std::uint64_t t0_ = 0;
  mutable std::uint64_t t_last_ = 0;
  double p_last_ = 0.0;       // loop correction at t_last_
  double freq_ = 0.0;         // dimensionless frequency correction
  double slew_rate_ = 0.0;    // dimensionless, sign of slew_left_
  double slew_left_ = 0.0;    // ns still to slew
  bool have_window_ = false;
  std::uint64_t window_t_ = 0;
  double window_error_ = 0.0;  // error without the loop's correction at window_t_
  bool have_estimate_ = false;
  double estimate_ = 0.0;      // frequency difference to the reference (dimensionless)
};

}  // namespace drivegate::ethercat::sim
