#include "adapters/link/udp_endpoint.hpp"

#include <arpa/inet.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <utility>

#include "adapters/link/interface.hpp"
#include "adapters/link/link.hpp"
#include "core/errno_text.hpp"
#include "core/fd_guard.hpp"

namespace drivegate::link {
namespace {

using core::errno_text;

sockaddr_in socket_address(const Ipv4Endpoint& e) noexcept {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(e.port);
  std::memcpy(&a.sin_addr.s_addr, e.address.data(), e.address.size());
  return a;
}

Ipv4Endpoint endpoint_of(const sockaddr_in& a) noexcept {
  Ipv4Endpoint e;
  std::memcpy(e.address.data(), &a.sin_addr.s_addr, e.address.size());
  e.port = ntohs(a.sin_port);
  return e;
}

const sockaddr* as_sockaddr(const sockaddr_in& a) noexcept { return reinterpret_cast<const sockaddr*>(&a); }

}  // namespace

UdpEndpoint::UdpEndpoint(UdpOptions options) : options_(std::move(options)) {}

UdpEndpoint::~UdpEndpoint() { close(); }

void UdpEndpoint::fail(const std::string& what) const { throw LinkError(std::string(options_.name) + ": " + what); }

void UdpEndpoint::open() {
  if (is_open()) return;
  const std::string& name = options_.interface;
  if (const std::string problem = interface_name_problem(name); !problem.empty()) fail(problem);
  const InterfaceName kernel_name = interface_name(name);

  core::FdGuard fd(::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (fd.get() < 0) fail("cannot create a UDP socket (socket: " + errno_text(errno) + ")");

  ifreq r = request_for(kernel_name);
  if (::ioctl(fd.get(), SIOCGIFFLAGS, &r) != 0) {
    const int e = errno;
    if (e == ENODEV) fail(no_interface_text(name, options_.peers));
    fail("cannot read the flags of '" + name + "' (SIOCGIFFLAGS: " + errno_text(e) + ")");
  }
  if ((r.ifr_flags & IFF_UP) == 0) fail(interface_down_text(name));

  r = request_for(kernel_name);
  if (::ioctl(fd.get(), SIOCGIFADDR, &r) != 0) {
    const int e = errno;
    if (e == EADDRNOTAVAIL) {
      fail("interface '" + name + "' has no IPv4 address; give it one, e.g. 'ip addr add 192.168.0.1/24 dev " + name +
           "' (an address in the " + options_.peers + "' subnet)");
    }
    fail("cannot read the IPv4 address of '" + name + "' (SIOCGIFADDR: " + errno_text(e) + ")");
  }
  sockaddr_in own{};
  std::memcpy(&own, &r.ifr_addr, sizeof own);
  Ipv4Endpoint wanted = endpoint_of(own);
  wanted.port = options_.port;
  const bool chosen = options_.address != std::array<std::uint8_t, 4>{};
  if (chosen) wanted.address = options_.address;

  if (::setsockopt(fd.get(), SOL_SOCKET, SO_BINDTODEVICE, kernel_name.data(), static_cast<socklen_t>(name.size())) != 0) {
    const int e = errno;
    if (e == EPERM || e == EACCES) {
      fail("no permission to bind a UDP socket to interface '" + name +
           "' (SO_BINDTODEVICE needs CAP_NET_RAW before Linux 5.7); run as root or give the binary cap_net_raw, "
           "e.g. setcap cap_net_raw+ep " + own_binary());
    }
    if (e == ENODEV) fail(no_interface_text(name, options_.peers));
    fail("cannot bind a UDP socket to interface '" + name + "' (SO_BINDTODEVICE: " + errno_text(e) + ")");
  }
  ::setsockopt(fd.get(), SOL_SOCKET, SO_RCVBUF, &options_.receive_buffer_bytes, sizeof(int));
  const int on = 1;
  // Without it (never seen on Linux since 2.6.33) drops are not counted; the socket works alike.
  (void)::setsockopt(fd.get(), SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);

  const sockaddr_in bind_to = socket_address(wanted);
  if (::bind(fd.get(), as_sockaddr(bind_to), sizeof bind_to) != 0) {
    const int e = errno;
    const std::string where = "UDP port " + std::to_string(options_.port) + " on " + ipv4_text(wanted.address) +
                              " (interface '" + name + "')";
    if (e == EADDRINUSE) {
      fail(where + " is in use by another socket; stop the program that holds it (see 'ss -ulpn sport = :" +
           std::to_string(options_.port) + "') or choose another port");
    }
    if (e == EACCES || e == EPERM) {
      fail("no permission to bind " + where + ": ports below 1024 need CAP_NET_BIND_SERVICE; run as root, choose "
           "a port from 1024 on, or give the binary cap_net_bind_service, e.g. setcap cap_net_bind_service+ep " +
           own_binary());
    }
    if (e == EADDRNOTAVAIL && chosen) {
      fail("address " + ipv4_text(wanted.address) + " is not on interface '" + name + "'; add it, e.g. 'ip addr add " +
           ipv4_text(wanted.address) + "/24 dev " + name + "'");
    }
    if (e == EADDRNOTAVAIL) fail("interface '" + name + "' lost its address " + ipv4_text(wanted.address) + " while opening");
    fail("cannot bind " + where + " (bind: " + errno_text(e) + ")");
  }
  sockaddr_in bound{};
  socklen_t length = sizeof bound;
  if (::getsockname(fd.get(), reinterpret_cast<sockaddr*>(&bound), &length) != 0) {
    fail("cannot read the UDP socket's address (getsockname: " + errno_text(errno) + ")");
  }
  local_ = endpoint_of(bound);
  kernel_drops_ = 0;
  fd_ = fd.release();
}

void UdpEndpoint::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  local_ = Ipv4Endpoint{};
}

DatagramStatus UdpEndpoint::send_to(const Ipv4Endpoint& to, std::span<const std::uint8_t> payload) noexcept {
  if (!sendable_datagram(payload)) {
    counters_.tx_invalid.add();
    return DatagramStatus::Invalid;
  }
  if (fd_ < 0) {
    counters_.tx_down.add();
    return DatagramStatus::Down;
  }
  const sockaddr_in address = socket_address(to);
  for (;;) {
    if (::sendto(fd_, payload.data(), payload.size(), MSG_DONTWAIT | MSG_NOSIGNAL, as_sockaddr(address), sizeof address) >= 0) {
      counters_.tx_datagrams.add();
      return DatagramStatus::Sent;
    }
    const int e = errno;
    if (e == EINTR) continue;
    if (e == EAGAIN || e == EWOULDBLOCK || e == ENOBUFS) {
      counters_.tx_busy.add();
      return DatagramStatus::Busy;
    }
    if (e == EMSGSIZE) {
      counters_.tx_invalid.add();
      return DatagramStatus::Invalid;
    }
    // ENETDOWN, ENETUNREACH, EHOSTUNREACH (the interface is down, no route, no ARP answer) and the
    // rest (EACCES: a broadcast address, EINVAL: port 0) alike: it did not go.
    counters_.tx_down.add();
    return DatagramStatus::Down;
  }
}

bool UdpEndpoint::receive_from(Datagram& out) noexcept {
  if (fd_ < 0) return false;
  for (;;) {
    sockaddr_in from{};
    iovec iov{out.bytes.data(), out.bytes.size()};
    // One SO_RXQ_OVFL message: a 4-byte count (CMSG_SPACE(4) is 24 on 64-bit Linux).
    alignas(cmsghdr) std::array<unsigned char, 32> control{};
    msghdr m{};
    m.msg_name = &from;
    m.msg_namelen = sizeof from;
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = control.data();
    m.msg_controllen = control.size();
    const ssize_t got = ::recvmsg(fd_, &m, MSG_DONTWAIT | MSG_TRUNC);
    if (got < 0) {
      if (errno == EINTR) continue;
      return false;  // EAGAIN: nothing pending
    }
    for (cmsghdr* c = CMSG_FIRSTHDR(&m); c != nullptr; c = CMSG_NXTHDR(&m, c)) {
      if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SO_RXQ_OVFL) continue;
      std::uint32_t drops = 0;
      std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
      counters_.rx_overflow.add(drops - kernel_drops_);
      kernel_drops_ = drops;
    }
    const auto length = static_cast<std::size_t>(got);
    if ((m.msg_flags & MSG_TRUNC) != 0 || length > out.bytes.size()) {
      counters_.rx_too_long.add();
      continue;
    }
    out.size = length;
    out.from = endpoint_of(from);
    counters_.rx_datagrams.add();
    return true;
  }
}

std::string UdpEndpoint::describe() const { return "udp " + options_.interface + " " + to_string(local_); }

}  // namespace drivegate::link
