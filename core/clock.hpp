#pragma once
// Time is injected (DESIGN.md §3): the daemon uses the monotonic clock, tests use virtual time.
// A time point is nanoseconds on CLOCK_MONOTONIC (or on the virtual time line).
#include <chrono>
#include <cstdint>

namespace drivegate::core {

using Duration = std::chrono::nanoseconds;
using TimePoint = std::chrono::time_point<std::chrono::steady_clock, Duration>;

class Clock {
 public:
  virtual ~Clock() = default;
  [[nodiscard]] virtual TimePoint now() const noexcept = 0;
};

class SteadyClock final : public Clock {
 public:
  [[nodiscard]] TimePoint now() const noexcept override {
    return std::chrono::time_point_cast<Duration>(std::chrono::steady_clock::now());
  }
};

// Virtual time for tests: it only moves when told to.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(TimePoint start = TimePoint{}) noexcept : now_(start) {}
  [[nodiscard]] TimePoint now() const noexcept override { return now_; }
  void advance(Duration d) noexcept { now_ += d; }
  void set(TimePoint t) noexcept { now_ = t; }

 private:
  TimePoint now_;
};

inline std::int64_t to_ns(TimePoint t) noexcept { return t.time_since_epoch().count(); }

}  // namespace drivegate::core
