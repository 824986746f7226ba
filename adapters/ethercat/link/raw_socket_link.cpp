#include "adapters/ethercat/link/raw_socket_link.hpp"

#include <arpa/inet.h>
#include <linux/if_arp.h>
#include <linux/if_ether.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "core/errno_text.hpp"
#include "core/fd_guard.hpp"

namespace drivegate::ethercat {
namespace {

// Older kernel headers: the option exists from Linux 4.20 on; an older kernel refuses it with
// ENOPROTOOPT and the pkttype fallback does the work.
#ifndef PACKET_IGNORE_OUTGOING
#define PACKET_IGNORE_OUTGOING 23
#endif

using core::errno_text;

[[noreturn]] void fail(const std::string& what) { throw LinkError("ethercat: " + what); }

std::string link_type_name(unsigned type) {
  switch (type) {
    case ARPHRD_LOOPBACK: return "loopback";
    case ARPHRD_NONE: return "none: a tun or other layer-3 device";
    case ARPHRD_PPP: return "PPP";
    case ARPHRD_CAN: return "CAN";
    case ARPHRD_TUNNEL:
    case ARPHRD_TUNNEL6:
    case ARPHRD_SIT:
    case ARPHRD_IPGRE: return "IP tunnel";
    case ARPHRD_INFINIBAND: return "InfiniBand";
    default: return "ARPHRD " + std::to_string(type);
  }
}

std::string own_binary() {
  std::array<char, 4096> path{};
  const ssize_t n = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  return n > 0 ? std::string(path.data(), static_cast<std::size_t>(n)) : std::string("/path/to/drivegated");
}

// An ifreq for `name` (already checked to fit).
ifreq request_for(const std::array<char, IFNAMSIZ>& name) noexcept {
  ifreq r{};
  std::memcpy(r.ifr_name, name.data(), name.size());
  return r;
}

bool is_link_error(int e) noexcept { return e == ENETDOWN || e == ENXIO || e == ENODEV || e == ENETUNREACH; }

// The reason text of open() failing for lack of CAP_NET_RAW, with the binary's path in the hint.
std::string no_raw_permission_text(const std::string& interface) {
  return "ethercat: no permission to open a raw Ethernet socket on '" + interface +
         "' (CAP_NET_RAW missing); run as root or give the binary cap_net_raw, e.g. setcap cap_net_raw+ep " +
         own_binary();
}

}  // namespace

RawSocketLink::RawSocketLink(RawSocketOptions options) : options_(std::move(options)) {
  // The headers point into this object's own arrays for its whole life; receive() sets the iovec
  // bases to the caller's buffers on each call.
  for (std::size_t i = 0; i < kLinkBatch; ++i) {
    tx_msgs_[i].msg_hdr.msg_iov = &tx_iov_[i];
    tx_msgs_[i].msg_hdr.msg_iovlen = 1;
    rx_msgs_[i].msg_hdr.msg_iov = &rx_iov_[i];
    rx_msgs_[i].msg_hdr.msg_iovlen = 1;
    rx_msgs_[i].msg_hdr.msg_name = &rx_from_[i];
  }
}

RawSocketLink::~RawSocketLink() { close(); }

void RawSocketLink::open() {
  if (is_open()) return;
  const std::string& name = options_.interface;
  if (name.empty() || name.size() >= IFNAMSIZ || name.find('/') != std::string::npos) {
    fail("'" + name + "' is not a network interface name (1 to " + std::to_string(IFNAMSIZ - 1) + " characters)");
  }
  name_.fill('\0');
  std::memcpy(name_.data(), name.data(), name.size());

  // Protocol 0: no frames are queued until bind() names the interface and the EtherType, so none
  // from other interfaces slip in between.
  core::FdGuard fd(::socket(AF_PACKET, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (fd.get() < 0) {
    const int e = errno;
    if (e == EPERM || e == EACCES) throw LinkError(no_raw_permission_text(name));
    if (e == EAFNOSUPPORT) fail("this kernel has no packet sockets (socket(AF_PACKET): " + errno_text(e) + "); it needs CONFIG_PACKET");
    fail("cannot create a raw Ethernet socket (socket(AF_PACKET): " + errno_text(e) + ")");
  }

  ifreq r = request_for(name_);
  if (::ioctl(fd.get(), SIOCGIFINDEX, &r) != 0) {
    const int e = errno;
    if (e == ENODEV) fail("no network interface '" + name + "'; give the name of the Ethernet port the slaves are on");
    fail("cannot look up interface '" + name + "' (SIOCGIFINDEX: " + errno_text(e) + ")");
  }
  const int index = r.ifr_ifindex;

  r = request_for(name_);
  if (::ioctl(fd.get(), SIOCGIFHWADDR, &r) != 0) {
    fail("cannot read the link type of '" + name + "' (SIOCGIFHWADDR: " + errno_text(errno) + ")");
  }
  if (r.ifr_hwaddr.sa_family != ARPHRD_ETHER) {
    fail("'" + name + "' is not an Ethernet interface (link type " + link_type_name(r.ifr_hwaddr.sa_family) +
         "); give the name of the Ethernet port the slaves are on");
  }

  r = request_for(name_);
  if (::ioctl(fd.get(), SIOCGIFFLAGS, &r) != 0) {
    fail("cannot read the flags of '" + name + "' (SIOCGIFFLAGS: " + errno_text(errno) + ")");
  }
  if ((r.ifr_flags & IFF_UP) == 0) fail("interface '" + name + "' is down; bring it up with 'ip link set " + name + " up'");

  ignore_outgoing_ = false;
  if (options_.ignore_outgoing) {
    const int on = 1;
    // ENOPROTOOPT before Linux 4.20: receive() drops PACKET_OUTGOING frames instead.
    ignore_outgoing_ = ::setsockopt(fd.get(), SOL_PACKET, PACKET_IGNORE_OUTGOING, &on, sizeof on) == 0;
  }
  // FORCE needs CAP_NET_ADMIN; without it the plain option, capped by net.core.[rw]mem_max.
  if (::setsockopt(fd.get(), SOL_SOCKET, SO_RCVBUFFORCE, &options_.receive_buffer_bytes, sizeof(int)) != 0) {
    ::setsockopt(fd.get(), SOL_SOCKET, SO_RCVBUF, &options_.receive_buffer_bytes, sizeof(int));
  }
  if (::setsockopt(fd.get(), SOL_SOCKET, SO_SNDBUFFORCE, &options_.send_buffer_bytes, sizeof(int)) != 0) {
    ::setsockopt(fd.get(), SOL_SOCKET, SO_SNDBUF, &options_.send_buffer_bytes, sizeof(int));
  }

  fd_ = fd.get();
  if (!bind_to(index)) {
    const int e = errno;
    fd_ = -1;
    if (e == ENETDOWN) fail("interface '" + name + "' is down; bring it up with 'ip link set " + name + " up'");
    if (e == ENODEV || e == ENXIO) fail("no network interface '" + name + "'; give the name of the Ethernet port the slaves are on");
    fail("cannot bind to '" + name + "' (bind: " + errno_text(e) + ")");
  }
  fd_ = fd.release();
  // Reset the kernel's drop count: drops before open are not ours.
  tpacket_stats stats{};
  socklen_t len = sizeof stats;
  ::getsockopt(fd_, SOL_PACKET, PACKET_STATISTICS, &stats, &len);

  state_.store(LinkState::Closed, std::memory_order_relaxed);
  check_now_ = false;
  set_state((r.ifr_flags & IFF_RUNNING) != 0 ? LinkState::Up : LinkState::NoCarrier);
}

bool RawSocketLink::bind_to(int ifindex) noexcept {
  sockaddr_ll address{};
  address.sll_family = AF_PACKET;
  address.sll_protocol = htons(options_.all_ethertypes ? std::uint16_t{ETH_P_ALL} : kEtherType);
  address.sll_ifindex = ifindex;
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    bound_ = false;
    return false;
  }
  ifindex_ = ifindex;
  bound_ = true;
  // Slaves pass a frame on with its destination unchanged: a master that sends to any address
  // but broadcast or the port's own still gets its frames back. Promiscuous for as long as this
  // socket lives (the kernel drops the membership with it); without it only such frames are lost.
  packet_mreq promisc{};
  promisc.mr_ifindex = ifindex;
  promisc.mr_type = PACKET_MR_PROMISC;
  (void)::setsockopt(fd_, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &promisc, sizeof promisc);
  return true;
}

void RawSocketLink::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  bound_ = false;
  ifindex_ = -1;
  state_.store(LinkState::Closed, std::memory_order_relaxed);
}

void RawSocketLink::set_state(LinkState s) noexcept {
  counters_.count_transition(state_.exchange(s, std::memory_order_relaxed), s);
}

void RawSocketLink::note_error(int e) noexcept {
  if (is_link_error(e)) check_now_ = true;
}

LinkState RawSocketLink::poll_state(core::TimePoint now) noexcept {
  if (fd_ < 0) return LinkState::Closed;
  if (!check_now_ && now < next_check_) return state();
  check_now_ = false;
  next_check_ = now + options_.state_interval;
  const LinkState s = refresh();
  set_state(s);
  return s;
}

LinkState RawSocketLink::refresh() noexcept {
  ifreq r = request_for(name_);
  if (::ioctl(fd_, SIOCGIFINDEX, &r) != 0) {
    // Gone (ENODEV); the kernel unbound the socket when the interface was unregistered.
    bound_ = false;
    return LinkState::Gone;
  }
  if (!bound_ || r.ifr_ifindex != ifindex_) {
    // The interface came back (a new index): the same socket, bound again.
    if (!bind_to(r.ifr_ifindex)) return LinkState::Gone;
  }
  r = request_for(name_);
  if (::ioctl(fd_, SIOCGIFFLAGS, &r) != 0) return LinkState::Gone;

  // The kernel's count of frames it dropped for a full receive buffer since the last read (reading
  // resets it).
  tpacket_stats stats{};
  socklen_t len = sizeof stats;
  if (::getsockopt(fd_, SOL_PACKET, PACKET_STATISTICS, &stats, &len) == 0) counters_.rx_overflow.add(stats.tp_drops);

  if ((r.ifr_flags & IFF_UP) == 0) return LinkState::AdminDown;
  // IFF_RUNNING is the operational state: carrier and, for a veth, the peer up.
  if ((r.ifr_flags & IFF_RUNNING) == 0) return LinkState::NoCarrier;
  if (state() != LinkState::Up) {
    // The kernel flagged the socket ENETDOWN when the interface went down; unread, that error would
    // fail the first send after the recovery. Reading SO_ERROR clears it.
    int pending = 0;
    len = sizeof pending;
    ::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &pending, &len);
  }
  return LinkState::Up;
}

SendResult RawSocketLink::send(std::span<const FrameView> frames) noexcept {
  SendResult r;
  // What is not sent: the staged frames of the batch from position `staged_from` to `staged_end`
  // (valid ones; the invalid ones among them are counted already) and every frame from `next` on,
  // not looked at yet (each counted invalid or unsent). Every frame is counted once.
  const auto stop = [&](std::size_t staged_from, std::size_t staged_end, std::size_t next, SendStatus why) {
    auto& cell = why == SendStatus::Busy ? counters_.tx_busy : counters_.tx_down;
    for (std::size_t k = staged_from; k < staged_end; ++k) {
      ++r.unsent;
      cell.add();
    }
    for (std::size_t i = next; i < frames.size(); ++i) {
      if (!sendable(frames[i])) {
        ++r.invalid;
        counters_.tx_invalid.add();
      } else {
        ++r.unsent;
        cell.add();
      }
    }
    r.status = why;
  };
  if (fd_ < 0) {
    stop(0, 0, 0, SendStatus::Down);
    return r;
  }

  std::size_t next = 0;
  while (next < frames.size()) {
    std::size_t count = 0;
    for (; next < frames.size() && count < kLinkBatch; ++next) {
      const FrameView f = frames[next];
      if (!sendable(f)) {
        ++r.invalid;
        counters_.tx_invalid.add();
        continue;
      }
      // sendmsg does not write through iov_base; iovec has no const variant.
      tx_iov_[count] = iovec{const_cast<std::uint8_t*>(f.data()), f.size()};
      ++count;
    }
    for (std::size_t done = 0; done < count;) {
      const int sent = ::sendmmsg(fd_, tx_msgs_.data() + done, static_cast<unsigned>(count - done), MSG_DONTWAIT);
      if (sent > 0) {
        done += static_cast<std::size_t>(sent);
        r.sent += static_cast<std::size_t>(sent);
        counters_.tx_frames.add(static_cast<std::uint64_t>(sent));
        continue;
      }
      const int e = errno;
      if (e == EINTR) continue;
      if (e == EMSGSIZE) {
        // Longer than the interface's MTU allows: this frame cannot go out here, the others can.
        ++r.invalid;
        counters_.tx_invalid.add();
        ++done;
        continue;
      }
      note_error(e);
      // A full queue (EAGAIN, ENOBUFS) is Busy; ENETDOWN, ENXIO and anything else is Down.
      stop(done, count, next, (e == EAGAIN || e == EWOULDBLOCK || e == ENOBUFS) ? SendStatus::Busy : SendStatus::Down);
      return r;
    }
  }
  return r;
}

std::size_t RawSocketLink::receive(std::span<FrameBuffer> out) noexcept {
  if (fd_ < 0) return 0;
  std::size_t n = 0;
  while (n < out.size()) {
    const std::size_t want = std::min(out.size() - n, kLinkBatch);
    for (std::size_t i = 0; i < want; ++i) {
      rx_iov_[i] = iovec{out[n + i].bytes.data(), out[n + i].bytes.size()};
      rx_msgs_[i].msg_hdr.msg_namelen = sizeof(sockaddr_ll);
      rx_msgs_[i].msg_hdr.msg_flags = 0;
    }
    // MSG_TRUNC: msg_len is the frame's real length even when it did not fit (too long).
    const int got = ::recvmmsg(fd_, rx_msgs_.data(), static_cast<unsigned>(want), MSG_DONTWAIT | MSG_TRUNC, nullptr);
    if (got < 0) {
      const int e = errno;
      if (e == EINTR) continue;
      note_error(e);  // EAGAIN: nothing pending; ENETDOWN: the interface went down (reported once)
      break;
    }
    const auto count = static_cast<std::size_t>(got);
    std::size_t kept = n;
    for (std::size_t i = 0; i < count; ++i) {
      const msghdr& m = rx_msgs_[i].msg_hdr;
      const std::size_t length = rx_msgs_[i].msg_len;
      if (rx_from_[i].sll_pkttype == PACKET_OUTGOING) {  // fallback for kernels before 4.20
        counters_.rx_own.add();
        continue;
      }
      FrameBuffer& slot = out[n + i];
      const FrameCheck c = (m.msg_flags & MSG_TRUNC) != 0 || length > slot.bytes.size()
                               ? FrameCheck::TooLong
                               : check_frame({slot.bytes.data(), length});
      if (c != FrameCheck::Ok) {
        counters_.count_drop(c);
        continue;
      }
      if (n + i != kept) std::memcpy(out[kept].bytes.data(), slot.bytes.data(), length);  // close a gap left by a drop
      out[kept].size = length;
      ++kept;
    }
    counters_.rx_frames.add(kept - n);
    n = kept;
    if (count < want) break;  // nothing more pending
  }
  return n;
}

std::string RawSocketLink::describe() const { return "raw ethernet " + options_.interface + " (AF_PACKET, EtherType 88A4h)"; }

}  // namespace drivegate::ethercat
