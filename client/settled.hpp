#pragma once
// A value that has settled: it has not changed for a quiet period (discovery that stops growing,
// an event history that stopped arriving). A predicate for the client's bounded waits.
#include <chrono>
#include <cstdint>
#include <optional>

namespace drivegate::client {

class Settled {
 public:
  explicit Settled(std::chrono::steady_clock::duration quiet) : quiet_(quiet) {}
  // True once `value` is the one of the calls since `quiet` ago (the first call starts the period).
  bool operator()(std::uint64_t value) {
    const auto now = std::chrono::steady_clock::now();
    if (!since_ || value != last_) {
      since_ = now;
      last_ = value;
    }
    return now - *since_ >= quiet_;
  }

 private:
  std::chrono::steady_clock::duration quiet_;
  std::uint64_t last_ = 0;
  std::optional<std::chrono::steady_clock::time_point> since_;
};

}  // namespace drivegate::client
