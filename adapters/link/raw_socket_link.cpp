#include "adapters/link/raw_socket_link.hpp"

#include <arpa/inet.h>
#include <linux/filter.h>
#include <linux/if_arp.h>
#include <linux/if_ether.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "adapters/link/interface.hpp"
#include "core/bytes.hpp"
#include "core/errno_text.hpp"
#include "core/fd_guard.hpp"

namespace drivegate::link {
namespace {

// Older kernel headers: the option exists from Linux 4.20 on; an older kernel refuses it with
// ENOPROTOOPT and the pkttype fallback does the work.
#ifndef PACKET_IGNORE_OUTGOING
#define PACKET_IGNORE_OUTGOING 23
#endif

using core::errno_text;

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

// Where a ring slot's sockaddr_ll starts: after the TPACKET_V2 header, aligned to
// TPACKET_ALIGNMENT (the kernel's TPACKET_ALIGN, written without its signed mask).
constexpr std::size_t kRingAddressOffset =
    (sizeof(tpacket2_hdr) + TPACKET_ALIGNMENT - 1) / TPACKET_ALIGNMENT * TPACKET_ALIGNMENT;

bool is_link_error(int e) noexcept { return e == ENETDOWN || e == ENXIO || e == ENODEV || e == ENETUNREACH; }

// The kernel filter of a link for tagged frames, bound to every EtherType: accept a frame whose
// EtherType is `ether_type`, behind the tag the kernel took off or not (the skb's protocol, which
// the ancillary load returns in host order), drop the rest before they are queued or copied.
std::array<sock_filter, 4> ether_type_filter(std::uint16_t ether_type) noexcept {
  return {{
      {BPF_LD | BPF_H | BPF_ABS, 0, 0, static_cast<std::uint32_t>(SKF_AD_OFF + SKF_AD_PROTOCOL)},
      {BPF_JMP | BPF_JEQ | BPF_K, 0, 1, ether_type},
      {BPF_RET | BPF_K, 0, 0, 0xFFFFFFFFu},
      {BPF_RET | BPF_K, 0, 0, 0},
  }};
}

}  // namespace

RawSocketLink::RawSocketLink(const FrameRules& rules, RawSocketOptions options)
    : rules_(rules), options_(std::move(options)) {
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

void RawSocketLink::fail(const std::string& what) const { throw LinkError(std::string(rules_.name) + ": " + what); }

std::uint16_t RawSocketLink::bound_protocol() const noexcept {
  return options_.all_ethertypes || rules_.vlan_tags ? std::uint16_t{ETH_P_ALL} : rules_.ether_type;
}

RawSocketLink::~RawSocketLink() { close(); }

void RawSocketLink::open() {
  if (is_open()) return;
  const std::string& name = options_.interface;
  if (const std::string problem = interface_name_problem(name); !problem.empty()) fail(problem);
  name_ = interface_name(name);

  // Protocol 0: no frames are queued until bind() names the interface and the EtherType, so none
  // from other interfaces slip in between.
  core::FdGuard fd(::socket(AF_PACKET, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (fd.get() < 0) {
    const int e = errno;
    if (e == EPERM || e == EACCES) {
      fail("no permission to open a raw Ethernet socket on '" + name +
           "' (CAP_NET_RAW missing); run as root or give the binary cap_net_raw, e.g. setcap cap_net_raw+ep " +
           own_binary());
    }
    if (e == EAFNOSUPPORT) fail("this kernel has no packet sockets (socket(AF_PACKET): " + errno_text(e) + "); it needs CONFIG_PACKET");
    fail("cannot create a raw Ethernet socket (socket(AF_PACKET): " + errno_text(e) + ")");
  }

  ifreq r = request_for(name_);
  if (::ioctl(fd.get(), SIOCGIFINDEX, &r) != 0) {
    const int e = errno;
    if (e == ENODEV) fail(no_interface_text(name, rules_.peers));
    fail("cannot look up interface '" + name + "' (SIOCGIFINDEX: " + errno_text(e) + ")");
  }
  const int index = r.ifr_ifindex;

  r = request_for(name_);
  if (::ioctl(fd.get(), SIOCGIFHWADDR, &r) != 0) {
    fail("cannot read the link type of '" + name + "' (SIOCGIFHWADDR: " + errno_text(errno) + ")");
  }
  if (r.ifr_hwaddr.sa_family != ARPHRD_ETHER) {
    fail("'" + name + "' is not an Ethernet interface (link type " + link_type_name(r.ifr_hwaddr.sa_family) +
         "); give the name of the Ethernet port the " + std::string(rules_.peers) + " are on");
  }

  r = request_for(name_);
  if (::ioctl(fd.get(), SIOCGIFFLAGS, &r) != 0) {
    fail("cannot read the flags of '" + name + "' (SIOCGIFFLAGS: " + errno_text(errno) + ")");
  }
  if ((r.ifr_flags & IFF_UP) == 0) fail(interface_down_text(name));

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

  if (rules_.vlan_tags) {
    // The tag of each frame comes as PACKET_AUXDATA; the filter goes on before bind() so that no
    // frame of another EtherType is queued in between.
    const int on = 1;
    if (::setsockopt(fd.get(), SOL_PACKET, PACKET_AUXDATA, &on, sizeof on) != 0) {
      fail("cannot ask for the VLAN tags of received frames (PACKET_AUXDATA: " + errno_text(errno) + ")");
    }
    if (!options_.all_ethertypes) {
      std::array<sock_filter, 4> code = ether_type_filter(rules_.ether_type);
      const sock_fprog program{static_cast<unsigned short>(code.size()), code.data()};
      if (::setsockopt(fd.get(), SOL_SOCKET, SO_ATTACH_FILTER, &program, sizeof program) != 0) {
        fail("cannot attach the EtherType filter (SO_ATTACH_FILTER: " + errno_text(errno) + ")");
      }
    }
  }

  if (options_.receive_ring) (void)map_ring(fd.get());  // else, or refused: recvmmsg

  fd_ = fd.get();
  if (!bind_to(index)) {
    const int e = errno;
    fd_ = -1;
    unmap_ring();
    if (e == ENETDOWN) fail(interface_down_text(name));
    if (e == ENODEV || e == ENXIO) fail(no_interface_text(name, rules_.peers));
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
  address.sll_protocol = htons(bound_protocol());
  address.sll_ifindex = ifindex;
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    bound_ = false;
    return false;
  }
  ifindex_ = ifindex;
  bound_ = true;
  // EtherCAT slaves pass a frame on with its destination unchanged: a master that sends to any
  // address but broadcast or the port's own still gets its frames back; PROFINET devices send DCP
  // Hello to a multicast address the port has not joined. Promiscuous for as long as this socket
  // lives (the kernel drops the membership with it); without it only such frames are lost.
  packet_mreq promisc{};
  promisc.mr_ifindex = ifindex;
  promisc.mr_type = PACKET_MR_PROMISC;
  (void)::setsockopt(fd_, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &promisc, sizeof promisc);
  return true;
}

bool RawSocketLink::map_ring(int fd) noexcept {
  // Slots of 2048 bytes hold the TPACKET_V2 header, the address and a whole frame of 1514 bytes
  // with room to spare (a longer one arrives cut: tp_snaplen < tp_len, dropped as too long); blocks
  // of 64 KiB, as many as receive_buffer_bytes asks for (at least one).
  constexpr std::size_t kFrameSize = 2048;
  constexpr std::size_t kBlockSize = 1U << 16;
  const std::size_t blocks =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::max(options_.receive_buffer_bytes, 0)) / kBlockSize);
  int version = TPACKET_V2;
  if (::setsockopt(fd, SOL_PACKET, PACKET_VERSION, &version, sizeof version) != 0) return false;
  tpacket_req req{};
  req.tp_block_size = kBlockSize;
  req.tp_block_nr = static_cast<unsigned>(blocks);
  req.tp_frame_size = kFrameSize;
  req.tp_frame_nr = static_cast<unsigned>(blocks * (kBlockSize / kFrameSize));
  if (::setsockopt(fd, SOL_PACKET, PACKET_RX_RING, &req, sizeof req) != 0) return false;
  const std::size_t bytes = blocks * kBlockSize;
  void* m = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (m == MAP_FAILED) {
    // Without the mapping the ring must go, or frames would queue where recvmmsg cannot see them.
    tpacket_req none{};
    (void)::setsockopt(fd, SOL_PACKET, PACKET_RX_RING, &none, sizeof none);
    return false;
  }
  ring_ = static_cast<std::uint8_t*>(m);
  ring_bytes_ = bytes;
  frame_size_ = kFrameSize;
  frame_count_ = req.tp_frame_nr;
  next_frame_ = 0;
  return true;
}

void RawSocketLink::unmap_ring() noexcept {
  if (ring_ != nullptr) ::munmap(ring_, ring_bytes_);
  ring_ = nullptr;
  ring_bytes_ = 0;
  frame_count_ = 0;
  next_frame_ = 0;
}

void RawSocketLink::close() noexcept {
  unmap_ring();  // before the socket: the mapping holds the ring
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
      if (!sendable(frames[i], rules_)) {
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
      if (!sendable(f, rules_)) {
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
  return ring_ != nullptr ? receive_ring(out) : receive_calls(out);
}

bool RawSocketLink::accept(FrameBuffer& slot, std::size_t length, bool truncated) noexcept {
  const FrameCheck c = truncated ? FrameCheck::TooLong : check_frame({slot.bytes.data(), length}, rules_);
  if (c != FrameCheck::Ok) {
    counters_.count_drop(c);
    return false;
  }
  slot.size = length;
  return true;
}

std::size_t RawSocketLink::receive_ring(std::span<FrameBuffer> out) noexcept {
  std::size_t n = 0;
  while (n < out.size()) {
    auto* h = reinterpret_cast<tpacket2_hdr*>(ring_ + next_frame_ * frame_size_);
    // The slot is ours once the kernel set TP_STATUS_USER; acquire pairs with the kernel's
    // barrier before it publishes the status, so the frame's bytes are complete.
    const std::uint32_t status = __atomic_load_n(&h->tp_status, __ATOMIC_ACQUIRE);
    if ((status & TP_STATUS_USER) == 0) break;
    const auto* from = reinterpret_cast<const sockaddr_ll*>(reinterpret_cast<const std::uint8_t*>(h) + kRingAddressOffset);
    if (from->sll_pkttype == PACKET_OUTGOING) {  // fallback for kernels before 4.20
      counters_.rx_own.add();
    } else {
      FrameBuffer& slot = out[n];
      std::size_t length = h->tp_snaplen;
      bool truncated = h->tp_len > h->tp_snaplen || length > kMaxUntaggedFrameBytes;
      if (!truncated) std::memcpy(slot.bytes.data(), reinterpret_cast<const std::uint8_t*>(h) + h->tp_mac, length);
      bool tag_ok = true;
      if (!truncated && rules_.vlan_tags && (status & TP_STATUS_VLAN_VALID) != 0) {
        const std::uint16_t tpid = (status & TP_STATUS_VLAN_TPID_VALID) != 0 ? h->tp_vlan_tpid : kVlanTpid;
        tag_ok = insert_tag(tpid, h->tp_vlan_tci, slot.bytes.data(), length);
      }
      if (!tag_ok) {
        counters_.count_drop(FrameCheck::WrongEtherType);
      } else if (accept(slot, length, truncated)) {
        ++n;
      }
    }
    __atomic_store_n(&h->tp_status, TP_STATUS_KERNEL, __ATOMIC_RELEASE);  // the slot back to the kernel
    next_frame_ = next_frame_ + 1 == frame_count_ ? 0 : next_frame_ + 1;
  }
  counters_.rx_frames.add(n);
  return n;
}

std::size_t RawSocketLink::receive_calls(std::span<FrameBuffer> out) noexcept {
  std::size_t n = 0;
  while (n < out.size()) {
    const std::size_t want = std::min(out.size() - n, kLinkBatch);
    for (std::size_t i = 0; i < want; ++i) {
      // The kernel hands every frame up without its tag: the longest is an untagged one, and with
      // tags the room for putting the tag back stays free.
      rx_iov_[i] = iovec{out[n + i].bytes.data(), kMaxUntaggedFrameBytes};
      msghdr& m = rx_msgs_[i].msg_hdr;
      m.msg_namelen = sizeof(sockaddr_ll);
      m.msg_flags = 0;
      m.msg_control = rules_.vlan_tags ? rx_control_[i].bytes.data() : nullptr;
      m.msg_controllen = rules_.vlan_tags ? rx_control_[i].bytes.size() : 0;
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
      std::size_t length = rx_msgs_[i].msg_len;
      if (rx_from_[i].sll_pkttype == PACKET_OUTGOING) {  // fallback for kernels before 4.20
        counters_.rx_own.add();
        continue;
      }
      FrameBuffer& slot = out[n + i];
      const bool truncated = (m.msg_flags & MSG_TRUNC) != 0 || length > rx_iov_[i].iov_len;
      if (!truncated && rules_.vlan_tags && !restore_tag(m, slot.bytes.data(), length)) {
        counters_.count_drop(FrameCheck::WrongEtherType);
        continue;
      }
      if (!accept(slot, length, truncated)) continue;
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

bool RawSocketLink::restore_tag(const msghdr& m, std::uint8_t* frame, std::size_t& length) noexcept {
  // msg_control is const in a const msghdr, CMSG_NXTHDR takes a mutable one; it only reads.
  auto& header = const_cast<msghdr&>(m);
  for (cmsghdr* c = CMSG_FIRSTHDR(&header); c != nullptr; c = CMSG_NXTHDR(&header, c)) {
    if (c->cmsg_level != SOL_PACKET || c->cmsg_type != PACKET_AUXDATA) continue;
    tpacket_auxdata aux{};
    std::memcpy(&aux, CMSG_DATA(c), sizeof aux);
    if ((aux.tp_status & TP_STATUS_VLAN_VALID) == 0) return true;
    const std::uint16_t tpid = (aux.tp_status & TP_STATUS_VLAN_TPID_VALID) != 0 ? aux.tp_vlan_tpid : kVlanTpid;
    return insert_tag(tpid, aux.tp_vlan_tci, frame, length);
  }
  return true;
}

bool RawSocketLink::insert_tag(std::uint16_t tpid, std::uint16_t tci, std::uint8_t* frame, std::size_t& length) noexcept {
  if (tpid != kVlanTpid) return false;
  if (length < kEtherTypeOffset) return true;  // too short to carry one: check_frame() refuses it
  std::memmove(frame + kEtherTypeOffset + kVlanTagBytes, frame + kEtherTypeOffset, length - kEtherTypeOffset);
  const std::span<std::uint8_t> tag(frame + kEtherTypeOffset, kVlanTagBytes);
  core::put_be16(tag, 0, kVlanTpid);
  core::put_be16(tag, 2, tci);
  length += kVlanTagBytes;
  return true;
}

std::string RawSocketLink::describe() const {
  std::array<char, 8> type{};
  std::snprintf(type.data(), type.size(), "%04Xh", rules_.ether_type);
  return "raw ethernet " + options_.interface + " (AF_PACKET, EtherType " + type.data() + ")";
}

}  // namespace drivegate::link
