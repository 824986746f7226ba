#pragma once
// The frames the sans-I/O engines want sent, in order. Fixed capacity, no allocation: engines push
// during a cycle, the bus drains it into the transport. A full queue refuses the frame and counts
// it; the engine that pushed treats that like a lost frame (timeouts take care of retrying).
#include <array>
#include <cstddef>
#include <cstdint>

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
  void pop() noexcept {
    if (size_ == 0) return;
    head_ = (head_ + 1) % Capacity;
    --size_;
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
