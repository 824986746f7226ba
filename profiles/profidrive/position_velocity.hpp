#pragma once
// The velocity of a drive whose telegram carries XIST_A but no NIST_A (telegrams 9, 352, 353
// [§4.3, §14]): the slope of the position over the last few fresh telegrams. The AKD updates its
// telegram every 16 ms or slower [§2], and a telegram's arrival jitters with the network and the
// controller's own cycle; a window of several updates keeps that jitter small against the span.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>

#include "core/clock.hpp"

namespace drivegate::profidrive {

class PositionVelocity {
 public:
  // Native velocity units per position count per second (the axis' velocity factor over its
  // position factor).
  explicit PositionVelocity(double velocity_per_count) noexcept : per_count_(velocity_per_count) {}

  // Forget the samples (the drive was lost; the next telegram starts afresh).
  void reset() noexcept {
    next_ = 0;
    count_ = 0;
  }

  // A fresh XIST_A received at `at`; the velocity over the window, in native units (0 until two
  // samples are in, saturated at the int32 range).
  std::int32_t add(std::int32_t xist_a, core::TimePoint at) noexcept {
    ring_[next_] = {xist_a, at};
    next_ = (next_ + 1) % kWindow;
    if (count_ < kWindow) ++count_;
    if (count_ < 2) return 0;
    const Sample& oldest = ring_[count_ < kWindow ? 0 : next_];
    const Sample& newest = ring_[(next_ + kWindow - 1) % kWindow];
    const double seconds = std::chrono::duration<double>(newest.at - oldest.at).count();
    if (!(seconds > 0)) return 0;
    // XIST_A wraps as a 32-bit counter [§17.2]: the difference modulo 2^32.
    const auto counts = static_cast<std::int32_t>(static_cast<std::uint32_t>(newest.xist_a) -
                                                  static_cast<std::uint32_t>(oldest.xist_a));
    const double v = counts / seconds * per_count_;
    if (v >= 2147483647.0) return INT32_MAX;
    if (v <= -2147483648.0) return INT32_MIN;
    return static_cast<std::int32_t>(v);
  }

 private:
  static constexpr std::size_t kWindow = 4;
  struct Sample {
    std::int32_t xist_a = 0;
    core::TimePoint at{};
  };
  double per_count_;
  std::array<Sample, kWindow> ring_{};
  std::size_t next_ = 0;
  std::size_t count_ = 0;
};

}  // namespace drivegate::profidrive
