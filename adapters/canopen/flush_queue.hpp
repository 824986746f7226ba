#pragma once
// Drains the engines' queue of frames into a transport, one send_batch per contiguous run of the
// ring (two when it wraps). A full transmit queue ends the call with the rest still queued (they go
// next time; the engines' timeouts cover what is late). Cyclic path: no allocation.
#include <cstddef>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/transport/transport.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen {

struct FlushResult {
  std::size_t sent = 0;
  std::size_t refused = 0;  // taken but not sent: invalid, or the transport down
  bool busy = false;        // the transmit queue was full; frames are still queued
};

template <std::size_t Capacity>
FlushResult flush_queue(FrameQueue<Capacity>& queue, Transport& transport, core::TimePoint now) noexcept {
  FlushResult f;
  while (!queue.empty()) {
    const SendBatchResult r = transport.send_batch(queue.front_run(), now);
    f.sent += r.sent;
    f.refused += r.taken - r.sent;
    queue.pop(r.taken);
    if (r.busy || r.taken == 0) {
      f.busy = r.busy;
      break;
    }
  }
  return f;
}

}  // namespace drivegate::canopen
