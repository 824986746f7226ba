#pragma once
// A bus' own events waiting for Bus::next_event() (core/bus.hpp): a fixed ring, oldest first, that
// drops and counts what does not fit instead of growing. One thread (the bus thread); no heap.
#include <array>
#include <cstddef>
#include <cstdint>

#include "core/command.hpp"

namespace drivegate::core {

template <std::size_t N>
class EventRing {
 public:
  [[nodiscard]] bool full() const noexcept { return count_ == N; }
  [[nodiscard]] bool empty() const noexcept { return count_ == 0; }
  // False (and counted in dropped()) when the ring is full.
  bool push(const Event& e) noexcept {
    if (full()) {
      ++dropped_;
      return false;
    }
    events_[(head_ + count_) % N] = e;
    ++count_;
    return true;
  }
  bool pop(Event& out) noexcept {
    if (empty()) return false;
    out = events_[head_];
    head_ = (head_ + 1) % N;
    --count_;
    return true;
  }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }

 private:
  std::array<Event, N> events_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace drivegate::core
