#pragma once
// TransportCounters as relaxed atomics (core::CounterCell): the one thread that runs
// send()/receive() writes them, any thread may read a snapshot (Transport::counters()).
#include "adapters/canopen/transport/transport.hpp"
#include "core/counter_cell.hpp"

namespace drivegate::canopen {

struct CounterCells {
  core::CounterCell rx_frames;
  core::CounterCell tx_frames;
  core::CounterCell rx_malformed;
  core::CounterCell rx_filtered;
  core::CounterCell tx_overflows;
  core::CounterCell error_frames;
  core::CounterCell bus_off;
  core::CounterCell restarts;

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
