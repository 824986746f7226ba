#pragma once
// A simulated line on a network interface (issue 9 "Simulator": drivegate-sim attached to one end
// of a veth pair). Frames the master sends arrive on the wire link (RawSocketLink: an AF_PACKET
// socket bound to the interface for EtherType 88A4h only; EtherCAT frames are broadcast, so no
// promiscuous mode), pass through the BuiltLine at the line's time, and what the last reachable
// slave returns goes back out of the same interface, as a real line's first slave sends it back
// on its port 0 [ETG.1000.4 §4]. Every 1 ms the slaves' PDI side runs without a frame too, so SM
// watchdogs expire while the master is silent.
//
// service(now) is non-blocking and allocates nothing; the time comes in (run_endpoint() reads
// CLOCK_MONOTONIC through core::SteadyClock). One thread services an endpoint, and the same thread
// applies the line's faults.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/line_builder.hpp"
#include "core/clock.hpp"

namespace drivegate::ethercat::sim {

struct SimEndpointCounters {
  std::uint64_t frames_in = 0;    // frames from the master (the wire link's receive)
  std::uint64_t frames_out = 0;   // answers sent back out
  std::uint64_t not_sent = 0;     // answers the wire link did not take (queue full, link down)
  std::uint64_t no_answer = 0;    // frames the line did not return (dropped, corrupted, no slave reachable)
  std::uint64_t ticks = 0;        // PDI cycles run without a frame
};

class SimEndpoint {
 public:
  // The PDI cycle of the slaves between frames.
  static constexpr core::Duration kTick = std::chrono::milliseconds(1);
  // Frames taken from the wire per receive call.
  static constexpr std::size_t kBatch = 16;

  // `wire` is opened by the caller (RawSocketLink::open(): its error says what to do).
  SimEndpoint(Link& wire, BuiltLine& line) noexcept : wire_(wire), line_(line) {}
  SimEndpoint(const SimEndpoint&) = delete;
  SimEndpoint& operator=(const SimEndpoint&) = delete;

  // Answers every frame waiting on the wire, then runs the PDI cycle when a tick is due (every kTick;
  // ticks missed in a stall are not made up: the slaves' watchdogs go by the time, not the count).
  void service(core::TimePoint now) noexcept;
  // When the next tick is due (service() must run by then).
  [[nodiscard]] core::TimePoint next_tick() const noexcept { return next_tick_; }
  // Readable when frames wait on the wire.
  [[nodiscard]] int wait_fd() const noexcept { return wire_.wait_fd(); }

  [[nodiscard]] BuiltLine& line() noexcept { return line_; }
  [[nodiscard]] Link& wire() noexcept { return wire_; }
  [[nodiscard]] const SimEndpointCounters& counters() const noexcept { return counters_; }

 private:
  Link& wire_;
  BuiltLine& line_;
  bool started_ = false;
  core::TimePoint next_tick_{};
  std::array<FrameBuffer, kBatch> rx_{};
  std::array<FrameBuffer, kBatch> answers_{};
  std::array<FrameView, kBatch> out_{};
  SimEndpointCounters counters_;
};

// Services `endpoint` until `stop` is set: waits for frames on its descriptor until the next tick,
// with the time of CLOCK_MONOTONIC. For an endpoint in a thread of its own (tests, a demo).
void run_endpoint(SimEndpoint& endpoint, const std::atomic<bool>& stop) noexcept;

}  // namespace drivegate::ethercat::sim
