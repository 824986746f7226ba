#pragma once
// Rate limit for repetitive log lines (a flood of rejected commands must not fill the journal):
// up to `burst` lines per `window`, the rest counted and reported once by whoever logs the summary.
// Control plane only; not thread-safe.
#include <chrono>
#include <cstdint>

namespace drivegate::daemon {

class LogLimiter {
 public:
  using Clock = std::chrono::steady_clock;

  explicit LogLimiter(std::uint32_t burst = 10, Clock::duration window = std::chrono::seconds(10)) noexcept
      : burst_(burst), window_(window) {}

  // True when this line may be logged; otherwise it is counted as suppressed.
  bool allow(Clock::time_point now) noexcept {
    if (now - window_start_ >= window_) {
      window_start_ = now;
      used_ = 0;
    }
    if (used_ < burst_) {
      ++used_;
      return true;
    }
    ++suppressed_;
    return false;
  }

  // Lines suppressed since the last call.
  std::uint64_t take_suppressed() noexcept {
    const std::uint64_t n = suppressed_;
    suppressed_ = 0;
    return n;
  }

 private:
  std::uint32_t burst_;
  Clock::duration window_;
  Clock::time_point window_start_{};
  std::uint32_t used_ = 0;
  std::uint64_t suppressed_ = 0;
};

}  // namespace drivegate::daemon
