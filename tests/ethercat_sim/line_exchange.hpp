#pragma once
// One master cycle's wire part against a simulated line, shared by the tests that drive the
// master's engines over a SimLine: the frames the engines queued pass the line at `now`, each
// answer goes back to the transactions, then `step` passes and what is still out is expired.
#include <array>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/sim/sim_line.hpp"
#include "core/clock.hpp"

namespace drivegate::ethercat::test {

inline void exchange_over_line(Transactions& tx, MemoryLink& link, sim::SimLine& line, core::TimePoint& now,
                               core::Duration step = std::chrono::milliseconds(1)) {
  line.set_time(static_cast<std::uint64_t>(core::to_ns(now)));
  for (const auto& f : tx.take_frames(now + step)) {
    link.send(FrameView(f.data(), f.size()));
    std::array<FrameBuffer, 1> rx;
    if (link.receive(rx) == 1) tx.on_frame(rx[0].view());
  }
  now += step;
  tx.expire(now);
}

}  // namespace drivegate::ethercat::test
