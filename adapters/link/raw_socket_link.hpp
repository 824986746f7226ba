#pragma once
// The production link: an AF_PACKET SOCK_RAW socket bound to one named Ethernet interface for the
// EtherType of the protocol's FrameRules (DESIGN.md §5), non-blocking, owned by the bus thread.
//
// - Outgoing frames are not read back. The kernel never shows a packet socket its own frames, and
//   shows the frames other local senders put out on the port only to sockets bound to every
//   EtherType; PACKET_IGNORE_OUTGOING (Linux 4.20+) keeps those away too, and without it (older
//   kernels) receive() drops what the kernel marks PACKET_OUTGOING and counts it (rx_own).
// - I/O is batched: send() writes up to kLinkBatch frames per sendmmsg. receive() takes the frames
//   from a receive ring the kernel fills in memory shared with the process (PACKET_RX_RING,
//   TPACKET_V2): no system call per cycle, only a look at the next slot's status word, and one
//   copy into the caller's FrameBuffer. Without the ring (RawSocketOptions::receive_ring false, or
//   a kernel that refuses it) it reads up to kLinkBatch per recvmmsg. Both paths check, restore
//   tags and count alike.
// - The link going down is a state, not an error: poll_state() reads the interface flags through
//   the socket (so in the socket's network namespace) at most once per check interval, and at once
//   after ENETDOWN/ENXIO from a send or receive. An interface that went down and up keeps the socket
//   (the kernel re-attaches it); one that disappeared and came back under the same name gets the
//   socket bound to it again. The socket, and wait_fd(), stay the same from open() to close().
// - 802.1Q tags (FrameRules::vlan_tags): the kernel takes the tag off every received frame before
//   a packet socket sees it, and tells only sockets bound to every EtherType what it was (in
//   PACKET_AUXDATA; for one bound to 8892h it clears the tag first). Such a link therefore binds to
//   every EtherType with a kernel filter (classic BPF on the frame's EtherType behind the tag) that
//   lets only the rules' EtherType through, and puts the tag back in front of it: receive() hands
//   up each frame as it was sent, tagged or not. A tag of another TPID than 8100h (802.1ad) is
//   dropped as a wrong EtherType. Sending a tagged frame is just its bytes.
#include <linux/if_packet.h>
#include <net/if.h>
#include <sys/socket.h>
#include <sys/uio.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <string>

#include "adapters/link/interface.hpp"
#include "adapters/link/link.hpp"

namespace drivegate::link {

// Frames per sendmmsg / recvmmsg call.
inline constexpr std::size_t kLinkBatch = 64;

struct RawSocketOptions {
  std::string interface;
  // How often poll_state() asks the kernel for the interface flags while nothing failed.
  core::Duration state_interval = std::chrono::milliseconds(10);
  // Socket buffer sizes asked for (SO_RCVBUFFORCE / SO_SNDBUFFORCE with CAP_NET_ADMIN, else capped
  // by net.core.rmem_max / wmem_max). 1 MiB holds several hundred full frames.
  int receive_buffer_bytes = 1 << 20;
  int send_buffer_bytes = 1 << 20;
  // PACKET_IGNORE_OUTGOING. Only a socket that sees every EtherType (below) is shown outgoing
  // frames at all; without the option (or before Linux 4.20) they are dropped by their pkttype.
  bool ignore_outgoing = true;
  // Bind to every EtherType (ETH_P_ALL) without a kernel filter and drop the others in receive(),
  // counted: for diagnosis, and for tests of the drop counters. Costs a copy of every frame on the
  // port.
  bool all_ethertypes = false;
  // Receive through a PACKET_RX_RING of receive_buffer_bytes (rounded to whole blocks) instead of
  // recvmmsg. A kernel that refuses the ring gets recvmmsg (receive_ring() says which).
  bool receive_ring = true;
};

// Not final: a protocol may name its own with its rules built in (ethercat::RawSocketLink).
class RawSocketLink : public Link {
 public:
  RawSocketLink(const FrameRules& rules, RawSocketOptions options);
  ~RawSocketLink() override;
  RawSocketLink(const RawSocketLink&) = delete;
  RawSocketLink& operator=(const RawSocketLink&) = delete;

  // Fails (LinkError, one line starting with the rules' name, "ethercat: ") without CAP_NET_RAW,
  // for a name that is no interface, an interface that is not Ethernet, and one that is
  // administratively down. An interface without carrier opens (state NoCarrier): the peers may not
  // be powered yet.
  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return fd_ >= 0; }

  using Link::send;
  SendResult send(std::span<const FrameView> frames) noexcept override;
  std::size_t receive(std::span<FrameBuffer> out) noexcept override;
  [[nodiscard]] int wait_fd() const noexcept override { return fd_; }
  LinkState poll_state(core::TimePoint now) noexcept override;
  [[nodiscard]] LinkState state() const noexcept override { return state_.load(std::memory_order_relaxed); }
  [[nodiscard]] LinkCounters counters() const noexcept override { return counters_.snapshot(); }
  [[nodiscard]] std::string describe() const override;

  // Whether the kernel took PACKET_IGNORE_OUTGOING (false: the pkttype fallback drops own frames).
  [[nodiscard]] bool ignores_outgoing() const noexcept { return ignore_outgoing_; }
  // Whether receive() reads the PACKET_RX_RING (false: recvmmsg).
  [[nodiscard]] bool receive_ring() const noexcept { return ring_ != nullptr; }

 private:
  // Reads the interface's index and flags through the socket, binds again when the interface came
  // back with another index, reads the kernel's drop count; returns the state seen.
  LinkState refresh() noexcept;
  bool bind_to(int ifindex) noexcept;
  // The EtherType the socket is bound to: the rules' own, or every one (ETH_P_ALL) for tags and
  // all_ethertypes.
  [[nodiscard]] std::uint16_t bound_protocol() const noexcept;
  // Puts the tag the kernel reported in m's control data back into `frame` (`length` grows by the
  // tag); false when the tag's TPID is not 8100h. A frame that came untagged stays as it is.
  static bool restore_tag(const msghdr& m, std::uint8_t* frame, std::size_t& length) noexcept;
  // Puts a tag back in front of the EtherType: `tci`, and `tpid` (false when it is not 8100h).
  static bool insert_tag(std::uint16_t tpid, std::uint16_t tci, std::uint8_t* frame, std::size_t& length) noexcept;
  // Sets up the receive ring on `fd` (before bind); false when the kernel refuses it.
  bool map_ring(int fd) noexcept;
  void unmap_ring() noexcept;
  std::size_t receive_ring(std::span<FrameBuffer> out) noexcept;
  std::size_t receive_calls(std::span<FrameBuffer> out) noexcept;
  // The checks of one received frame already in `slot` (`length` bytes; `truncated` when the
  // kernel cut it): counted and false when dropped.
  bool accept(FrameBuffer& slot, std::size_t length, bool truncated) noexcept;
  [[noreturn]] void fail(const std::string& what) const;
  void set_state(LinkState s) noexcept;
  // A send or receive error: what it says about the link (ENETDOWN, ENXIO, ENODEV) makes the next
  // poll_state() ask the kernel at once.
  void note_error(int e) noexcept;

  FrameRules rules_;
  RawSocketOptions options_;
  InterfaceName name_{};
  int fd_ = -1;
  int ifindex_ = -1;
  bool bound_ = false;
  bool ignore_outgoing_ = false;
  bool check_now_ = true;
  core::TimePoint next_check_{};
  std::atomic<LinkState> state_{LinkState::Closed};
  LinkCounterCells counters_;

  std::array<mmsghdr, kLinkBatch> tx_msgs_{};
  std::array<iovec, kLinkBatch> tx_iov_{};
  std::array<mmsghdr, kLinkBatch> rx_msgs_{};
  std::array<iovec, kLinkBatch> rx_iov_{};
  std::array<sockaddr_ll, kLinkBatch> rx_from_{};
  // Per received message: room for one PACKET_AUXDATA control message (CMSG_SPACE of a 20-byte
  // tpacket_auxdata is 40 on 64-bit Linux); used with tags only.
  struct alignas(cmsghdr) Control {
    std::array<unsigned char, 64> bytes{};
  };
  std::array<Control, kLinkBatch> rx_control_{};

  // The receive ring: frame_count_ slots of frame_size_ bytes in one mapping, read in order.
  std::uint8_t* ring_ = nullptr;
  std::size_t ring_bytes_ = 0;
  std::size_t frame_size_ = 0;
  std::size_t frame_count_ = 0;
  std::size_t next_frame_ = 0;
};

}  // namespace drivegate::link
