#pragma once
// A UDP socket on one named interface's IPv4 address (DESIGN.md §5): PROFINET's DCE/RPC connection
// management runs over it (the device side listens on UDP port 34964, the controller sends from a
// port the kernel picks). Non-blocking, one datagram per call, owned by one thread.
//
// open() reads the interface's (primary) IPv4 address (or takes the one the options name), binds the socket to the interface
// (SO_BINDTODEVICE: datagrams go out on that port whatever the routing table says) and to that
// address and port. It fails with one line each for: a name that is no interface, an interface
// that is down, one without an IPv4 address (with the `ip addr add` that fixes it), a port in use,
// and missing permission (a port below 1024 without CAP_NET_BIND_SERVICE; SO_BINDTODEVICE without
// CAP_NET_RAW on kernels before 5.7). The address is read once: one given to the interface later
// takes a close() and open().
//
// Drops are counted: datagrams longer than kMaxDatagramBytes (rx_too_long), and those the kernel
// dropped for a full receive buffer (SO_RXQ_OVFL, reported with the next datagram: rx_overflow).
#include <netinet/in.h>

#include <array>
#include <cstdint>
#include <string>

#include "adapters/link/datagram.hpp"

namespace drivegate::link {

struct UdpOptions {
  std::string interface;
  // 0: a port the kernel picks (a controller's); a device side listens on its protocol's port.
  std::uint16_t port = 0;
  // 0.0.0.0: the interface's (primary) IPv4 address; otherwise this one, which must be one of the
  // interface's (a simulator with several devices behind one port, each on its own address).
  std::array<std::uint8_t, 4> address{};
  // The first word of every error line ("profinet"), and what is on the other end of the cable
  // ("devices"), for the hints.
  const char* name = "";
  const char* peers = "";
  // SO_RCVBUF asked for (capped by net.core.rmem_max).
  int receive_buffer_bytes = 1 << 18;
};

class UdpEndpoint final : public DatagramPort {
 public:
  explicit UdpEndpoint(UdpOptions options);
  ~UdpEndpoint() override;
  UdpEndpoint(const UdpEndpoint&) = delete;
  UdpEndpoint& operator=(const UdpEndpoint&) = delete;

  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return fd_ >= 0; }
  [[nodiscard]] Ipv4Endpoint local() const noexcept override { return local_; }

  DatagramStatus send_to(const Ipv4Endpoint& to, std::span<const std::uint8_t> payload) noexcept override;
  bool receive_from(Datagram& out) noexcept override;

  [[nodiscard]] int wait_fd() const noexcept override { return fd_; }
  [[nodiscard]] DatagramCounters counters() const noexcept override { return counters_.snapshot(); }
  [[nodiscard]] std::string describe() const override;

 private:
  [[noreturn]] void fail(const std::string& what) const;

  UdpOptions options_;
  int fd_ = -1;
  Ipv4Endpoint local_{};
  std::uint32_t kernel_drops_ = 0;  // the last SO_RXQ_OVFL count (the socket's drops since open)
  DatagramCounterCells counters_;
};

}  // namespace drivegate::link
