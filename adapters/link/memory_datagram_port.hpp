#pragma once
// An in-process DatagramPort for unit tests of the engines that talk UDP (DESIGN.md §5): two ports
// connected as a pair reach each other at their local endpoints, like two hosts on one subnet. A
// datagram sent to the peer's endpoint waits in the peer's receive queue with this port's endpoint
// as its source; one sent anywhere else goes nowhere (as to an address nobody has), counted as sent
// as UDP would. deliver() puts a datagram from any source into the queue (a third host, a stray
// answer). The queue has a fixed capacity given at construction; a datagram that does not fit is
// dropped and counted (rx_overflow), as a full socket buffer would.
//
// One thread, no locks; counters() may be read from any thread.
#include <cstddef>
#include <string>
#include <vector>

#include "adapters/link/datagram.hpp"

namespace drivegate::link {

class MemoryDatagramPort final : public DatagramPort {
 public:
  // `capacity`: datagrams the receive queue holds (allocated here, never in the cyclic path).
  explicit MemoryDatagramPort(const Ipv4Endpoint& local, std::size_t capacity = 16);
  ~MemoryDatagramPort() override;
  MemoryDatagramPort(const MemoryDatagramPort&) = delete;
  MemoryDatagramPort& operator=(const MemoryDatagramPort&) = delete;

  // Datagrams sent on `a` to b's endpoint arrive at `b` and the other way round. Replaces earlier
  // peers of either.
  static void connect(MemoryDatagramPort& a, MemoryDatagramPort& b) noexcept;

  // Queues one datagram from `from`. False when it was dropped: the port is closed, the payload is
  // longer than kMaxDatagramBytes (rx_too_long), or the queue is full (rx_overflow).
  bool deliver(const Ipv4Endpoint& from, std::span<const std::uint8_t> payload) noexcept;
  [[nodiscard]] std::size_t pending() const noexcept { return count_; }

  void open() override { open_ = true; }
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return open_; }
  [[nodiscard]] Ipv4Endpoint local() const noexcept override { return open_ ? local_ : Ipv4Endpoint{}; }
  DatagramStatus send_to(const Ipv4Endpoint& to, std::span<const std::uint8_t> payload) noexcept override;
  bool receive_from(Datagram& out) noexcept override;
  [[nodiscard]] int wait_fd() const noexcept override { return -1; }
  [[nodiscard]] DatagramCounters counters() const noexcept override { return counters_.snapshot(); }
  [[nodiscard]] std::string describe() const override;

 private:
  void detach() noexcept;

  Ipv4Endpoint local_;
  std::vector<Datagram> slots_;
  std::size_t head_ = 0;   // oldest queued datagram
  std::size_t count_ = 0;  // queued datagrams
  MemoryDatagramPort* peer_ = nullptr;
  bool open_ = false;
  DatagramCounterCells counters_;
};

}  // namespace drivegate::link
