#pragma once
// A virtual CAN bus that several processes share: one UDP datagram per frame to an IPv4 multicast
// group, each a msgpack map as python-can's udp_multicast interface writes it (msgpack_frame.hpp),
// so python-can peers sit on the same bus (DESIGN.md §5).
//
// Two sockets: the receive socket is bound to INADDR_ANY:port and joins the group on the chosen
// interface; frames are sent from a second socket so that our own datagrams, which multicast
// loopback delivers to every member on this host including us, are recognised by their source
// (the send socket's address and port) and dropped. There is no arbitration, no bus-off and no
// error state: controller_state() is always Active.
//
// I/O is batched: receive() reads what is pending with recvmmsg, up to kUdpBatch datagrams a call,
// and send_batch() writes up to kUdpBatch frames with one sendmmsg. An echo is recognised from the
// datagram's source address alone, before any decoding.
//
// Reception time stamps are the `now` passed to receive(): the kernel's SO_TIMESTAMPNS would be
// on CLOCK_REALTIME, not on the monotonic/virtual line frames are compared against.
#include <array>
#include <cstdint>
#include <string>

#include <netinet/in.h>
#include <sys/socket.h>

#include "adapters/canopen/transport/counter_cells.hpp"
#include "adapters/canopen/transport/msgpack_frame.hpp"
#include "adapters/canopen/transport/transport.hpp"

namespace drivegate::canopen {

// Datagrams per recvmmsg / sendmmsg call.
inline constexpr std::size_t kUdpBatch = 64;

struct UdpMulticastOptions {
  std::string group = "239.74.163.2";  // python-can's default IPv4 group
  std::uint16_t port = 43113;          // python-can's default port
  // The IPv4 address of the interface to join and send on. Loopback keeps the bus on this host.
  std::string interface_address = "127.0.0.1";
  int ttl = 1;  // IP_MULTICAST_TTL: 1 = this link only
};

class UdpMulticastTransport final : public Transport {
 public:
  explicit UdpMulticastTransport(UdpMulticastOptions options);
  ~UdpMulticastTransport() override;
  UdpMulticastTransport(const UdpMulticastTransport&) = delete;
  UdpMulticastTransport& operator=(const UdpMulticastTransport&) = delete;

  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return rx_fd_ >= 0; }

  std::size_t receive(std::span<CanFrame> out, core::TimePoint now) noexcept override;
  SendResult send(const CanFrame& frame, core::TimePoint now) noexcept override;
  SendBatchResult send_batch(std::span<const CanFrame> frames, core::TimePoint now) noexcept override;

  [[nodiscard]] ControllerState controller_state() const noexcept override { return ControllerState::Active; }
  [[nodiscard]] TransportCounters counters() const noexcept override { return counters_.snapshot(); }
  [[nodiscard]] std::string describe() const override;
  [[nodiscard]] int wait_fd() const noexcept override { return rx_fd_; }

 private:
  UdpMulticastOptions options_;
  int rx_fd_ = -1;
  int tx_fd_ = -1;
  // The send socket's address as our datagrams carry it (never 0.0.0.0), to recognise our echoes.
  sockaddr_in own_source_{};
  CounterCells counters_;
  // python-can reads up to 4096 bytes per datagram; a longer one is malformed for us too.
  static constexpr std::size_t kRxDatagramMax = 4096;
  std::array<std::array<std::uint8_t, kRxDatagramMax>, kUdpBatch> rx_buffers_{};
  std::array<sockaddr_in, kUdpBatch> rx_sources_{};
  std::array<iovec, kUdpBatch> rx_iov_{};
  std::array<mmsghdr, kUdpBatch> rx_msgs_{};
  std::array<std::array<std::uint8_t, kMsgpackFrameMaxSize>, kUdpBatch> tx_buffers_{};
  std::array<iovec, kUdpBatch> tx_iov_{};
  std::array<mmsghdr, kUdpBatch> tx_msgs_{};
  std::array<std::size_t, kUdpBatch> tx_frame_of_{};  // the frame (index into the batch) of each message
};

}  // namespace drivegate::canopen
