#pragma once
// An in-process link for unit tests and the in-process simulator (DESIGN.md §5): frames sent go to
// a FrameSink (the simulated line, called synchronously and in order) or to a connected peer
// MemoryLink's receive queue; what the sink or peer hands back with deliver() waits in this link's
// receive queue. The queue has a fixed capacity given at construction; a frame that does not fit is
// dropped and counted (rx_overflow), as a full socket buffer would. Received frames are checked like
// the raw socket's (check_frame() by the link's FrameRules: too short, too long, wrong EtherType are
// dropped and counted). A tagged frame stays tagged, as RawSocketLink hands it up.
//
// One thread, no locks: the sink runs inside send() on the caller's thread and may call deliver()
// from there. counters() and state() may be read from any thread.
#include <atomic>
#include <cstddef>
#include <string>
#include <vector>

#include "adapters/link/link.hpp"

namespace drivegate::link {

// Where a MemoryLink's sent frames go. on_frame() runs inside MemoryLink::send().
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual void on_frame(FrameView frame) noexcept = 0;
};

// Not final: a protocol may name its own with its rules built in (ethercat::MemoryLink).
class MemoryLink : public Link {
 public:
  // `capacity`: frames the receive queue holds (allocated here, never in the cyclic path).
  explicit MemoryLink(const FrameRules& rules, std::size_t capacity = 256);
  ~MemoryLink() override;
  MemoryLink(const MemoryLink&) = delete;
  MemoryLink& operator=(const MemoryLink&) = delete;

  // Frames sent on `a` arrive in b's receive queue and the other way round (a cable). Replaces a
  // sink or an earlier peer of either.
  static void connect(MemoryLink& a, MemoryLink& b) noexcept;
  // Frames sent go to `sink` (nullptr: nowhere, counted as sent). Replaces a peer.
  void set_sink(FrameSink* sink) noexcept;

  // Queues one frame for receive(). False when it was dropped: the link is not open and up, the
  // frame failed check_frame(), or the queue is full (each counted).
  bool deliver(FrameView frame) noexcept;
  [[nodiscard]] std::size_t pending() const noexcept { return count_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return slots_.size(); }

  // The wire's state as a test wants it (Up after construction). While it is not Up, send()
  // returns Down and deliver() drops frames (the wire is cut). Transitions are counted here.
  void set_wire_state(LinkState s) noexcept;

  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return open_.load(std::memory_order_relaxed); }
  using Link::send;
  SendResult send(std::span<const FrameView> frames) noexcept override;
  std::size_t receive(std::span<FrameBuffer> out) noexcept override;
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  LinkState poll_state(core::TimePoint now) noexcept override;
  [[nodiscard]] LinkState state() const noexcept override;
  [[nodiscard]] LinkCounters counters() const noexcept override { return counters_.snapshot(); }
  [[nodiscard]] std::string describe() const override;

 private:
  void detach() noexcept;

  FrameRules rules_;
  std::vector<FrameBuffer> slots_;
  std::size_t head_ = 0;   // oldest queued frame
  std::size_t count_ = 0;  // queued frames
  FrameSink* sink_ = nullptr;
  MemoryLink* peer_ = nullptr;
  std::atomic<LinkState> wire_{LinkState::Up};
  std::atomic<bool> open_{false};  // atomic for state() readers on other threads
  LinkCounterCells counters_;
};

}  // namespace drivegate::link
