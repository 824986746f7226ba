#pragma once
// The link a bus thread sends its raw Ethernet frames on and reads them back from (DESIGN.md §2
// rule 5, §5), shared by EtherCAT (EtherType 88A4h) and PROFINET (8892h): it moves whole Ethernet
// frames (destination, source, [802.1Q tag,] EtherType, payload; no FCS) as bytes and does not
// interpret them beyond the Ethernet header. Which EtherType, how short a frame may be, whether
// tagged frames belong to the protocol and the prefix of error lines are the protocol's FrameRules.
// Implementations: RawSocketLink (AF_PACKET on a named interface, production and veth tests) and
// MemoryLink (in-process, unit tests and the in-process simulators).
//
// send(), receive(), poll_state(), state() and counters() are the cyclic path: non-blocking, no heap
// allocation, no lock, no logging. open() may allocate and throws LinkError with one line a person
// can act on. One thread (the bus thread) uses a link; state() and counters() may be read from any.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "core/clock.hpp"
#include "core/counter_cell.hpp"

namespace drivegate::link {

class LinkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Ethernet II [IEEE 802.3 §3.2]: destination 6, source 6, EtherType 2 (big-endian at offset 12,
// §3.2.6); an IEEE 802.1Q tag (TPID 8100h + TCI: PCP bits 13-15, DEI bit 12, VID bits 0-11) goes
// between the source and the EtherType. Frames are not padded to the 60-byte minimum here: veth
// does not pad, a NIC pads on its own. The FCS is never part of a frame here.
inline constexpr std::size_t kEthernetHeaderBytes = 14;
inline constexpr std::size_t kEtherTypeOffset = 12;
inline constexpr std::uint16_t kVlanTpid = 0x8100;
inline constexpr std::size_t kVlanTagBytes = 4;
inline constexpr std::size_t kMaxUntaggedFrameBytes = 1514;  // 1500 bytes of payload [IEEE 802.3 §3.2.7]
inline constexpr std::size_t kMaxFrameBytes = kMaxUntaggedFrameBytes + kVlanTagBytes;  // tagged

// What a protocol's frames are, for the link that carries them.
struct FrameRules {
  std::uint16_t ether_type = 0;
  // The shortest untagged frame of the protocol: the Ethernet header and the protocol's own header
  // (a tagged one may be kVlanTagBytes longer).
  std::size_t min_frame_bytes = kEthernetHeaderBytes;
  // Whether frames with an 802.1Q tag (TPID 8100h) in front of `ether_type` are the protocol's:
  // PROFINET's RT frames carry a priority tag, EtherCAT's frames are untagged.
  bool vlan_tags = false;
  // The first word of every error line ("ethercat" -> "ethercat: no network interface ...").
  const char* name = "";
  // What is on the other end of the cable, for the hints ("slaves", "devices").
  const char* peers = "";
};

// One frame to send: the whole Ethernet frame.
using FrameView = std::span<const std::uint8_t>;

// Whether `frame` carries an 802.1Q tag: TPID 8100h where the EtherType would be.
constexpr bool has_vlan_tag(std::span<const std::uint8_t> frame) noexcept {
  return frame.size() >= kEthernetHeaderBytes && frame[kEtherTypeOffset] == (kVlanTpid >> 8) &&
         frame[kEtherTypeOffset + 1] == (kVlanTpid & 0xFF);
}

// Whether a frame's length lets it go on the link: rules.min_frame_bytes to kMaxUntaggedFrameBytes,
// both kVlanTagBytes more for a tagged frame when the rules allow tags. send() skips other frames
// (counted invalid); check_frame() refuses received ones by the same rule.
constexpr bool sendable(FrameView frame, const FrameRules& rules) noexcept {
  const std::size_t tag = rules.vlan_tags && has_vlan_tag(frame) ? kVlanTagBytes : 0;
  return frame.size() >= rules.min_frame_bytes + tag && frame.size() <= kMaxUntaggedFrameBytes + tag;
}

// What a received frame is, by its length and EtherType only.
enum class FrameCheck : std::uint8_t { Ok, TooShort, TooLong, WrongEtherType };
// The EtherType is big-endian at offset 12 [IEEE 802.3 §3.2.6], or at 16 behind an 802.1Q tag when
// the rules allow tags; without them a tagged frame (8100h) counts as a wrong EtherType.
[[nodiscard]] FrameCheck check_frame(std::span<const std::uint8_t> frame, const FrameRules& rules) noexcept;

// One received frame in memory the caller owns (the socket writes straight into `bytes`).
struct FrameBuffer {
  std::array<std::uint8_t, kMaxFrameBytes> bytes{};
  std::size_t size = 0;

  [[nodiscard]] std::span<const std::uint8_t> view() const noexcept { return {bytes.data(), size}; }
};

enum class LinkState : std::uint8_t {
  Closed,     // not opened (or closed)
  Up,         // interface up with carrier: frames can flow
  AdminDown,  // the interface is administratively down (`ip link set IFACE down`)
  NoCarrier,  // up, but no carrier: cable unplugged, the first slave or the veth peer is down
  Gone,       // the interface no longer exists (unplugged USB adapter, deleted veth)
};
const char* to_string(LinkState s) noexcept;

enum class SendStatus : std::uint8_t {
  Sent,  // every valid frame was handed to the interface
  Busy,  // the transmit queue was full: that frame and the ones after it were not sent
  Down,  // the link is down or closed: that frame and the ones after it were not sent
};

// What send() did with its frames, front first: sent + invalid + unsent == frames given. Invalid
// frames (not sendable()) are skipped and the rest go on.
struct SendResult {
  std::size_t sent = 0;
  std::size_t invalid = 0;
  std::size_t unsent = 0;
  SendStatus status = SendStatus::Sent;
};

struct LinkCounters {
  std::uint64_t tx_frames = 0;
  std::uint64_t tx_invalid = 0;         // refused by send(): too short or too long
  std::uint64_t tx_busy = 0;            // not sent: transmit queue full
  std::uint64_t tx_down = 0;            // not sent: link down or closed
  std::uint64_t rx_frames = 0;          // delivered by receive()
  std::uint64_t rx_too_short = 0;       // dropped: shorter than the rules' minimum
  std::uint64_t rx_too_long = 0;        // dropped: longer than an Ethernet frame
  std::uint64_t rx_wrong_ethertype = 0; // dropped: not the rules' EtherType (or a tag they refuse)
  std::uint64_t rx_own = 0;             // dropped: an outgoing frame of this host seen back
  std::uint64_t rx_overflow = 0;        // dropped before we saw it: receive queue full
  std::uint64_t link_downs = 0;         // transitions from Up to any down state
  std::uint64_t link_ups = 0;           // recoveries: transitions back to Up
};

// LinkCounters as relaxed atomics (core::CounterCell): the bus thread writes them, any thread may
// read a snapshot.
struct LinkCounterCells {
  core::CounterCell tx_frames, tx_invalid, tx_busy, tx_down;
  core::CounterCell rx_frames, rx_too_short, rx_too_long, rx_wrong_ethertype, rx_own, rx_overflow;
  core::CounterCell link_downs, link_ups;

  [[nodiscard]] LinkCounters snapshot() const noexcept;
  // Counts a received frame that check_frame() refused.
  void count_drop(FrameCheck c) noexcept;
  // Counts a change of the link state: Up to any other state is a link down, back to Up from a
  // down state a link up (from Closed it is an open, not a recovery).
  void count_transition(LinkState before, LinkState after) noexcept;
};

class Link {
 public:
  virtual ~Link() = default;

  // Opens the link; throws LinkError with one line that says what is wrong and what to do.
  virtual void open() = 0;
  virtual void close() noexcept = 0;
  [[nodiscard]] virtual bool is_open() const noexcept = 0;

  // Non-blocking send of whole Ethernet frames in order, in as few system calls as the link allows.
  virtual SendResult send(std::span<const FrameView> frames) noexcept = 0;
  SendResult send(FrameView frame) noexcept { return send(std::span<const FrameView>(&frame, 1)); }

  // Non-blocking: fills out[0..n) with everything pending (up to out.size()), oldest first, and
  // returns n, each frame as it was sent (a tagged frame with its tag). Frames that check_frame()
  // refuses, and our own outgoing frames, are dropped and counted, never returned.
  virtual std::size_t receive(std::span<FrameBuffer> out) noexcept = 0;

  // A file descriptor that becomes readable when frames arrive (and reports POLLERR when the link
  // goes down), or -1. It stays the same from open() to close().
  [[nodiscard]] virtual int wait_fd() const noexcept = 0;

  // The link state, cheap enough to call every cycle: it asks the kernel at most once per the
  // link's check interval (and at once after a send or receive error), and recovers the link when
  // its interface is back. `now` is the bus thread's time.
  virtual LinkState poll_state(core::TimePoint now) noexcept = 0;
  // The state poll_state() last saw; any thread.
  [[nodiscard]] virtual LinkState state() const noexcept = 0;

  // Any thread.
  [[nodiscard]] virtual LinkCounters counters() const noexcept = 0;
  // "raw ethernet eth1", "memory link", ...
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace drivegate::link
