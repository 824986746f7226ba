#pragma once
// An in-process CAN bus for tests and benchmarks that emulates the wire: frames take the time they
// take at the bit rate (wire/bit_timing.hpp), the lowest identifier wins arbitration, a frame
// reaches the other nodes when its transmission ends, queues fill up, controllers go bus-off.
//
//   InprocBus bus(500'000);
//   auto master = bus.connect();  auto drive = bus.connect();
//   master->open(); drive->open();
//   master->send(frame, t);  ...  drive->receive(frames, t + 270us);
//
// Time is whatever `now` the callers pass to send()/receive()/advance(), so virtual time works;
// a `now` earlier than one already seen counts as that one. Each endpoint's transmit queue is FIFO
// (like a SocketCAN interface queue); when the medium becomes free, the heads of the queues that
// were waiting by then arbitrate, lowest identifier first with the real bit order (a base frame
// beats an extended one with the same 11 leading bits, a data frame beats a remote frame).
// A transmission is only started once `now` has passed its start time, so every frame sent at the
// same instant takes part in the arbitration. bitrate 0 is an instant bus: a frame is delivered
// within the send() call.
//
// Single-threaded: the bus and all its endpoints are used from one thread (counters() of an
// endpoint may still be read from any). The bus outlives its endpoints. Memory is allocated in the
// constructor and in connect(); send(), receive() and advance() allocate nothing.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "adapters/canopen/transport/transport.hpp"

namespace drivegate::canopen {

class InprocBus;

// One node's connection to the bus.
class InprocEndpoint final : public Transport {
 public:
  ~InprocEndpoint() override;  // closes: frames it has queued are discarded
  InprocEndpoint(const InprocEndpoint&) = delete;
  InprocEndpoint& operator=(const InprocEndpoint&) = delete;

  void open() override;
  // Discards the queued frames in both directions; a closed endpoint receives nothing.
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override;

  std::size_t receive(std::span<CanFrame> out, core::TimePoint now) noexcept override;
  // Queues the frame; Busy when this endpoint's queue holds its limit, Down while bus-off.
  SendResult send(const CanFrame& frame, core::TimePoint now) noexcept override;

  [[nodiscard]] ControllerState controller_state() const noexcept override;
  [[nodiscard]] TransportCounters counters() const noexcept override;
  [[nodiscard]] std::string describe() const override;

  [[nodiscard]] std::size_t index() const noexcept { return index_; }
  // Frames delivered to this endpoint and not yet received (as far as the medium has been run).
  [[nodiscard]] std::size_t available() const noexcept;

 private:
  friend class InprocBus;
  InprocEndpoint(InprocBus& bus, std::size_t index) noexcept : bus_(&bus), index_(index) {}

  InprocBus* bus_;
  std::size_t index_;
};

struct InprocBusOptions {
  std::size_t max_endpoints = 16;
  std::size_t tx_queue_capacity = 64;    // per endpoint; set_tx_queue_limit() can lower the limit
  std::size_t rx_queue_capacity = 4096;  // per endpoint; frames that find it full are lost
};

struct InprocBusStats {
  std::uint64_t frames = 0;       // transmissions completed (dropped and corrupted ones included)
  std::uint64_t dropped = 0;      // transmitted but delivered to nobody (drop_next)
  std::uint64_t corrupted = 0;    // delivered altered (corrupt_next)
  std::uint64_t flushed = 0;      // queued frames discarded because their sender went bus-off
  std::uint64_t rx_overruns = 0;  // deliveries lost to a full receive queue
  core::Duration busy{};          // time the medium carried completed frames
};

// How corrupt_next() alters a frame: its data XOR `xor_mask`, and its dlc replaced when given
// (0..8; a receiver then sees a frame of the wrong length).
struct Corruption {
  std::array<std::uint8_t, 8> xor_mask{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
  std::optional<std::uint8_t> dlc;
};

class InprocBus {
 public:
  // bitrate in bit/s; 0 = instant (no transmission time, no arbitration delay).
  explicit InprocBus(std::uint32_t bitrate, InprocBusOptions options = {});
  ~InprocBus();
  InprocBus(const InprocBus&) = delete;
  InprocBus& operator=(const InprocBus&) = delete;

  // A new endpoint (closed until open()). Throws std::length_error after max_endpoints calls.
  std::unique_ptr<InprocEndpoint> connect();

  // Runs the medium up to `now`: finishes transmissions, delivers, starts the next ones.
  void advance(core::TimePoint now) noexcept;

  // --- fault emulation -------------------------------------------------------------------------
  // Caps how many frames the endpoint may have queued (at most tx_queue_capacity).
  void set_tx_queue_limit(const InprocEndpoint& endpoint, std::size_t limit) noexcept;
  // The endpoint's controller goes bus-off (its queued frames are discarded, it neither sends nor
  // receives; a frame it has on the wire completes) or recovers (error active, a restart).
  void set_bus_off(const InprocEndpoint& endpoint, bool bus_off) noexcept;
  // The next `count` frames with identifier `id` occupy the medium but reach nobody / reach the
  // receivers altered. Up to 16 hooks may be pending; more throw std::length_error.
  void drop_next(std::uint32_t id, std::size_t count);
  void corrupt_next(std::uint32_t id, std::size_t count, Corruption how = {});

  // --- statistics ----------------------------------------------------------------------------
  [[nodiscard]] InprocBusStats stats() const noexcept;
  // Bus load: the share of time the medium was busy from the window start (the last
  // start_load_window(), or TimePoint{}) to `now`, 0..1.
  void start_load_window(core::TimePoint now) noexcept;
  [[nodiscard]] double load(core::TimePoint now) noexcept;
  // Nothing queued and nothing on the wire.
  [[nodiscard]] bool idle() const noexcept;
  // The earliest `now` at which advance() has something to do (a transmission ends, a queued frame
  // starts); TimePoint::max() when idle. For a caller that runs the medium on a real clock.
  [[nodiscard]] core::TimePoint next_change() const noexcept;
  [[nodiscard]] std::uint32_t bitrate() const noexcept { return bitrate_; }

 private:
  friend class InprocEndpoint;
  struct Slot;
  struct Hook;
  struct Transmission;

  void add_hook(std::uint32_t id, std::size_t count, bool drop, const Corruption& how);
  SendResult enqueue(std::size_t slot, const CanFrame& frame, core::TimePoint now) noexcept;
  std::size_t take(std::size_t slot, std::span<CanFrame> out, core::TimePoint now) noexcept;
  bool start_next(core::TimePoint now) noexcept;
  void finish() noexcept;

  std::uint32_t bitrate_;
  InprocBusOptions options_;
  std::unique_ptr<Slot[]> slots_;
  std::size_t slot_count_ = 0;
  std::unique_ptr<Hook[]> hooks_;
  std::unique_ptr<Transmission> wire_;  // the frame on the medium
  core::TimePoint last_now_{};
  core::TimePoint free_since_{};  // when the medium last became free
  core::TimePoint window_start_{};
  core::Duration window_busy_{};  // transmission time started in the window (may reach past now)
  InprocBusStats stats_;
};

}  // namespace drivegate::canopen
