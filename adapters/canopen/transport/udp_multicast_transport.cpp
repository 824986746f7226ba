#include "adapters/canopen/transport/udp_multicast_transport.hpp"

#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <utility>

#include "adapters/canopen/transport/batch_send.hpp"
#include "core/errno_text.hpp"
#include "core/fd_guard.hpp"

namespace drivegate::canopen {
namespace {

// Datagrams receive() may read and drop (own echoes, junk) on top of the frames it returns, so
// that a flood of them cannot hold the cycle thread for long; the rest waits for the next call.
constexpr std::size_t kDiscardBudget = 64;

using core::errno_text;

[[noreturn]] void fail(const std::string& what) { throw TransportError("udp-multicast: " + what); }

int udp_socket() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) fail("cannot create a UDP socket (socket: " + errno_text(errno) + ")");
  return fd;
}

template <typename T>
void set_option(int fd, int level, int name, const T& value, const char* name_text) {
  if (::setsockopt(fd, level, name, &value, sizeof value) != 0) {
    fail(std::string("cannot configure the socket (") + name_text + ": " + errno_text(errno) + ")");
  }
}

[[noreturn]] void no_such_interface(const std::string& address, const char* call, int e) {
  fail("no local interface has the address " + address + " (" + call + ": " + errno_text(e) +
       "); give the IPv4 address of the interface to use, e.g. 127.0.0.1");
}

sockaddr* as_sockaddr(sockaddr_in& a) noexcept { return reinterpret_cast<sockaddr*>(&a); }

}  // namespace

UdpMulticastTransport::UdpMulticastTransport(UdpMulticastOptions options) : options_(std::move(options)) {
  // The message headers point into this object's own buffers for its whole life.
  for (std::size_t i = 0; i < kUdpBatch; ++i) {
    rx_iov_[i] = iovec{rx_buffers_[i].data(), rx_buffers_[i].size()};
    rx_msgs_[i].msg_hdr.msg_iov = &rx_iov_[i];
    rx_msgs_[i].msg_hdr.msg_iovlen = 1;
    tx_iov_[i] = iovec{tx_buffers_[i].data(), 0};
    // No msg_name: the send socket is connected to the group (open()).
    tx_msgs_[i].msg_hdr.msg_iov = &tx_iov_[i];
    tx_msgs_[i].msg_hdr.msg_iovlen = 1;
  }
}

UdpMulticastTransport::~UdpMulticastTransport() { close(); }

void UdpMulticastTransport::open() {
  if (is_open()) return;
  in_addr group{};
  // 224.0.0.0/4: the top four bits 1110 (the IN_MULTICAST macro is an old-style cast).
  if (::inet_pton(AF_INET, options_.group.c_str(), &group) != 1 || (ntohl(group.s_addr) >> 28) != 0xE) {
    fail("'" + options_.group + "' is not an IPv4 multicast group address (224.0.0.0 to 239.255.255.255)");
  }
  in_addr interface{};
  if (::inet_pton(AF_INET, options_.interface_address.c_str(), &interface) != 1) {
    fail("interface address '" + options_.interface_address +
         "' is not an IPv4 address; give the address of the interface to use, e.g. 127.0.0.1");
  }
  if (options_.port == 0) fail("port 0 is not a port a bus can share (1..65535)");
  if (options_.ttl < 0 || options_.ttl > 255) fail("TTL " + std::to_string(options_.ttl) + " is not in 0..255");

  core::FdGuard rx(udp_socket());
  // Every process on the bus binds the same port.
  set_option(rx.get(), SOL_SOCKET, SO_REUSEADDR, int{1}, "SO_REUSEADDR");
  sockaddr_in any{};
  any.sin_family = AF_INET;
  any.sin_port = htons(options_.port);
  any.sin_addr.s_addr = 0;  // INADDR_ANY (the macro is an old-style cast)
  if (::bind(rx.get(), as_sockaddr(any), sizeof any) != 0) {
    const int e = errno;
    if (e == EADDRINUSE) {
      fail("port " + std::to_string(options_.port) + " is taken by a socket that does not share it (bind: " +
           errno_text(e) + "); stop that program or choose another port");
    }
    fail("cannot bind port " + std::to_string(options_.port) + " (bind: " + errno_text(e) + ")");
  }
  ip_mreq membership{};
  membership.imr_multiaddr = group;
  membership.imr_interface = interface;
  if (::setsockopt(rx.get(), IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership) != 0) {
    no_such_interface(options_.interface_address, "IP_ADD_MEMBERSHIP", errno);
  }
  // Only our group: by default Linux also hands this socket datagrams for groups that other
  // sockets on the host joined on the same port.
  set_option(rx.get(), IPPROTO_IP, IP_MULTICAST_ALL, int{0}, "IP_MULTICAST_ALL");

  core::FdGuard tx(udp_socket());
  // Bound to the interface address (the kernel picks the port); 0.0.0.0 leaves the address to the
  // route, chosen at connect() below.
  sockaddr_in source{};
  source.sin_family = AF_INET;
  source.sin_addr = interface;
  if (::bind(tx.get(), as_sockaddr(source), sizeof source) != 0) no_such_interface(options_.interface_address, "bind", errno);
  set_option(tx.get(), IPPROTO_IP, IP_MULTICAST_IF, interface, "IP_MULTICAST_IF");
  set_option(tx.get(), IPPROTO_IP, IP_MULTICAST_TTL, options_.ttl, "IP_MULTICAST_TTL");
  // Other members on this host (python-can peers, simulated drives) receive through loopback.
  set_option(tx.get(), IPPROTO_IP, IP_MULTICAST_LOOP, int{1}, "IP_MULTICAST_LOOP");
  // Connected to the group so that the kernel fixes the source address now: with interface
  // 0.0.0.0 the socket is bound to 0.0.0.0, while our datagrams (and so our echoes) carry the
  // address of the interface the route picks. getsockname() then reports that real source.
  sockaddr_in destination{};
  destination.sin_family = AF_INET;
  destination.sin_port = htons(options_.port);
  destination.sin_addr = group;
  if (::connect(tx.get(), as_sockaddr(destination), sizeof destination) != 0) {
    fail("cannot send to " + options_.group + " from " + options_.interface_address + " (connect: " +
         errno_text(errno) + "); give the IPv4 address of the interface to use, or add a route for the group");
  }
  socklen_t len = sizeof own_source_;
  if (::getsockname(tx.get(), as_sockaddr(own_source_), &len) != 0) {
    fail("cannot read the send socket's address (getsockname: " + errno_text(errno) + ")");
  }
  rx_fd_ = rx.release();
  tx_fd_ = tx.release();
}

void UdpMulticastTransport::close() noexcept {
  if (rx_fd_ >= 0) ::close(rx_fd_);
  if (tx_fd_ >= 0) ::close(tx_fd_);
  rx_fd_ = tx_fd_ = -1;
}

std::size_t UdpMulticastTransport::receive(std::span<CanFrame> out, core::TimePoint now) noexcept {
  if (rx_fd_ < 0) return 0;
  std::size_t n = 0;
  std::size_t budget = out.size() + kDiscardBudget;  // datagrams this call may read
  while (n < out.size() && budget > 0) {
    // No more datagrams than frames still fit in `out`: every one of them may be a frame.
    const std::size_t want = std::min({out.size() - n, budget, kUdpBatch});
    for (std::size_t i = 0; i < want; ++i) {
      rx_msgs_[i].msg_hdr.msg_name = &rx_sources_[i];
      rx_msgs_[i].msg_hdr.msg_namelen = sizeof rx_sources_[i];
    }
    // MSG_TRUNC: each datagram's real length, so that one longer than its buffer is not decoded cut.
    const int got = ::recvmmsg(rx_fd_, rx_msgs_.data(), static_cast<unsigned>(want), MSG_DONTWAIT | MSG_TRUNC, nullptr);
    if (got < 0) {
      if (errno == EINTR) continue;
      break;  // EAGAIN: nothing more; anything else is retried on the next call
    }
    const auto count = static_cast<std::size_t>(got);
    budget -= count;
    for (std::size_t i = 0; i < count; ++i) {
      // Our own echo, known by its source before anything is decoded.
      const sockaddr_in& from = rx_sources_[i];
      if (from.sin_port == own_source_.sin_port && from.sin_addr.s_addr == own_source_.sin_addr.s_addr) {
        counters_.rx_filtered.add();
        continue;
      }
      const std::size_t size = rx_msgs_[i].msg_len;
      if (size > kRxDatagramMax || (rx_msgs_[i].msg_hdr.msg_flags & MSG_TRUNC) != 0) {
        counters_.rx_malformed.add();
        continue;
      }
      const auto d = decode_msgpack_frame({rx_buffers_[i].data(), size});
      if (d.error != MsgpackFrameError::None) {
        counters_.rx_malformed.add();
        continue;
      }
      if (d.error_frame) {  // a peer's controller report; there is no controller here to change
        counters_.error_frames.add();
        continue;
      }
      out[n] = d.frame;
      out[n].timestamp = now;
      ++n;
      counters_.rx_frames.add();
    }
    if (count < want) break;  // nothing more pending
  }
  return n;
}

SendResult UdpMulticastTransport::send(const CanFrame& frame, core::TimePoint now) noexcept {
  if (tx_fd_ < 0) return SendResult::Down;
  if (!frame.valid()) return SendResult::Invalid;
  const auto r = send_batch({&frame, 1}, now);
  return r.busy ? SendResult::Busy : r.sent == 1 ? SendResult::Sent : SendResult::Down;
}

SendBatchResult UdpMulticastTransport::send_batch(std::span<const CanFrame> frames, core::TimePoint now) noexcept {
  SendBatchResult r;
  if (tx_fd_ < 0) {  // every frame Down
    r.taken = frames.size();
    return r;
  }
  // Receivers replace the timestamp with their reception time; ours is for captures only.
  const double seconds = static_cast<double>(core::to_ns(now)) * 1e-9;
  const auto stage = [this, seconds](std::size_t slot, const CanFrame& f) {
    tx_iov_[slot].iov_len = encode_msgpack_frame(f, seconds, tx_buffers_[slot]);
  };
  return send_in_batches(tx_fd_, frames, tx_msgs_, tx_frame_of_, counters_, stage);
}

std::string UdpMulticastTransport::describe() const {
  return "udp-multicast " + options_.group + ":" + std::to_string(options_.port) + " on " + options_.interface_address;
}

}  // namespace drivegate::canopen
