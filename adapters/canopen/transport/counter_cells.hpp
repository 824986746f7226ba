#pragma once
// TransportCounters as relaxed atomics: the one thread that runs send()/receive() writes them, any
// thread may read a snapshot (Transport::counters()). A single writer needs no read-modify-write,
// so an increment is a relaxed load and store, as cheap as a plain increment.
#include <atomic>
#include <cstdint>

#include "adapters/canopen/transport/transport.hpp"

namespace drivegate::canopen {

class CounterCell {
 public:
  void add(std::uint64_t n = 1) noexcept { v_.store(v_.load(std::memory_order_relaxed) + n, std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t get() const noexcept { return v_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> v_{0};
};

struct CounterCells {
  CounterCell rx_frames;
  CounterCell tx_frames;
  CounterCell rx_malformed;
  CounterCell rx_filtered;
  CounterCell tx_overflows;
  CounterCell error_frames;
  CounterCell bus_off;
  CounterCell restarts;

  [[nodiscard]] TransportCounters snapshot() const noexcept {
    TransportCounters c;
    c.rx_frames = rx_frames.get();
    c.tx_frames = tx_frames.get();
    c.rx_malformed = rx_malformed.get();
    c.rx_filtered = rx_filtered.get();
    c.tx_overflows = tx_overflows.get();
    c.error_frames = error_frames.get();
    c.bus_off = bus_off.get();
    c.restarts = restarts.get();
    return c;
  }
};

}  // namespace drivegate::canopen
