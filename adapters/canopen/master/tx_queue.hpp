#pragma once
// The frames the sans-I/O engines want sent, in order. Fixed capacity, no allocation: engines push
// during a cycle, the bus drains it into the transport. A full queue refuses the frame and counts
// it; the engine that pushed treats that like a lost frame (timeouts take care of retrying).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/canopen/wire/can_frame.hpp"

namespace drivegate::canopen {

template <std::size_t Capacity>
class FrameQueue {
 public:
  bool push(const CanFrame& f) noexcept {
    if (size_ == Capacity) {
      ++overflows_;
      return false;
    }
    frames_[(head_ + size_) % Capacity] = f;
    ++size_;
    return true;
  }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] const CanFrame& front() const noexcept { return frames_[head_]; }
  void pop() noexcept { pop(1); }
  // The frames from the front that lie contiguous in memory (all of them, or those up to the end of
  // the ring; the rest follow once these are popped): what a transport sends in one batch.
  [[nodiscard]] std::span<const CanFrame> front_run() const noexcept {
    return {frames_.data() + head_, std::min(size_, Capacity - head_)};
  }
  // Removes the first min(n, size()) frames.
  void pop(std::size_t n) noexcept {
    n = std::min(n, size_);
    head_ = (head_ + n) % Capacity;
    size_ -= n;
  }
  void clear() noexcept { head_ = size_ = 0; }
  [[nodiscard]] std::uint64_t overflows() const noexcept { return overflows_; }

 private:
  std::array<CanFrame, Capacity> frames_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::uint64_t overflows_ = 0;
};

// What every engine writes into: enough for one SYNC cycle of 127 nodes with 4 RPDOs each plus
// the acyclic traffic of a cycle.
using TxQueue = FrameQueue<1024>;

}  // namespace drivegate::canopen
