#pragma once
// A counter as a relaxed atomic: the one thread that counts writes it, any thread may read it (for a
// snapshot of a transport's or link's counters). A single writer needs no read-modify-write, so an
// increment is a relaxed load and store, as cheap as a plain increment.
#include <atomic>
#include <cstdint>

namespace drivegate::core {

class CounterCell {
 public:
  void add(std::uint64_t n = 1) noexcept { v_.store(v_.load(std::memory_order_relaxed) + n, std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t get() const noexcept { return v_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> v_{0};
};

}  // namespace drivegate::core
