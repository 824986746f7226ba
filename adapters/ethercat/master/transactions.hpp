#pragma once
// Datagram transactions: the engines (LineBoot, CoeSdoClient, later the cyclic process data) queue
// datagrams here; they are packed into EtherCAT frames (several datagrams per frame, M bit set on
// all but the last, up to the 1514-byte Ethernet limit) [ETG.1000.4 §5.3-§5.4]. Every frame gets
// one index byte, written into the index field of each of its datagrams; the slaves return the
// frame with the same layout, and the frame is matched back by that index (and each datagram's
// command, length and address checked) [ETG.1000.4 §5.4: the index is the master's identifier of
// the datagram and is not changed by the slaves].
//
// Results go back to the requester through DatagramOwner::on_result(): the data span points into
// the received frame (valid during the call only: in place, no copy, no allocation). A frame that
// is not back when expire(now) finds its deadline passed is counted lost, and its datagrams are
// reported Lost. A received frame with an index not in flight (a late frame, another master's) is
// counted "foreign" and dropped; a malformed one (FrameParser error) or one whose datagrams do not
// match what was sent is counted and dropped (its datagrams are reported lost at the deadline).
//
// Fixed capacities (kMaxFrames frame buffers, kMaxDatagramsPerFrame datagrams each); nothing here
// allocates. One thread (the bus thread) uses an instance.
//
// Use per cycle:  engines queue()  ->  take_frames(deadline) -> link.send()  ->  on_frame() for each
//                 received frame  ->  expire(now) at the end of the cycle.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/ethercat/wire/frame.hpp"
#include "core/clock.hpp"

namespace drivegate::ethercat {

enum class DatagramOutcome : std::uint8_t {
  Answered,  // the frame came back: data and WKC as the slaves left them
  Lost,      // the frame was not back by its deadline (or was dropped as malformed / mismatched)
};
std::string_view to_string(DatagramOutcome o) noexcept;

struct DatagramAnswer {
  DatagramOutcome outcome = DatagramOutcome::Lost;
  Command command = Command::NOP;
  std::uint32_t address = 0;                // as sent
  std::span<const std::uint8_t> data{};     // Answered: the returned data, in the received frame
  std::uint16_t wkc = 0;                    // Answered: working counter
};

// Whoever queues datagrams receives their outcome here, once per datagram, with the tag it gave.
class DatagramOwner {
 public:
  virtual void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept = 0;

 protected:
  DatagramOwner() = default;
  DatagramOwner(const DatagramOwner&) = default;
  DatagramOwner& operator=(const DatagramOwner&) = default;
  ~DatagramOwner() = default;
};

struct TransactionCounters {
  std::uint64_t datagrams_queued = 0;
  std::uint64_t datagrams_answered = 0;
  std::uint64_t datagrams_lost = 0;
  std::uint64_t queue_full = 0;      // queue() refused: no frame buffer or datagram slot free
  std::uint64_t too_long = 0;        // queue() refused: data longer than one frame carries
  std::uint64_t frames_sent = 0;     // handed out by take_frames()
  std::uint64_t frames_returned = 0; // matched and delivered
  std::uint64_t frames_lost = 0;     // deadline passed
  std::uint64_t foreign = 0;         // well-formed, but the index is not in flight
  std::uint64_t malformed = 0;       // FrameParser refused it (reasons in frame_errors())
  std::uint64_t mismatched = 0;      // index in flight, but the datagrams differ from those sent
};

class Transactions {
 public:
  // Frame buffers. A cycle sends up to ProcessImage::kMaxFrames (4) cyclic frames plus the
  // mailbox and set-up traffic after them (a frame or a few), and a frame stays in flight until the
  // next cycle's receive matches or expires it (one more cycle when that cycle comes early against
  // its deadline): two cycles of 4 + 4 frames. 8 held only one frame's image and its mailbox traffic.
  static constexpr std::size_t kMaxFrames = 16;
  // As many as a frame can hold (wire/frame.hpp).
  static constexpr std::size_t kMaxDatagramsPerFrame = ethercat::kMaxDatagramsPerFrame;

  explicit Transactions(const MacAddress& source = MacAddress{0x02, 0, 0, 0, 0, 0x01}) noexcept;

  // Queues a datagram of `length` data bytes (the first data.size() taken from `data`, the rest
  // zero) for the next take_frames(). Returns false (counted) when no room is left this cycle or
  // the length exceeds what one frame carries. `owner` may be null (result dropped).
  bool queue(DatagramOwner* owner, std::uint32_t tag, Command command, std::uint32_t address,
             std::uint16_t length, std::span<const std::uint8_t> data = {}) noexcept;

  // Finishes the frames queued since the last call and returns them, in queue order, for the
  // link; they are in flight until `deadline`. The spans stay valid until the frames return or are
  // expired.
  std::span<const std::span<const std::uint8_t>> take_frames(core::TimePoint deadline) noexcept;

  // A frame received from the link. Returns true when it matched a frame in flight (results
  // delivered).
  bool on_frame(std::span<const std::uint8_t> frame) noexcept;

  // Frames in flight whose deadline is at or before `now` are lost; their datagrams are reported.
  void expire(core::TimePoint now) noexcept;

  // The owner goes away: its datagrams still queued or in flight are no longer reported.
  void forget(const DatagramOwner* owner) noexcept;

  [[nodiscard]] std::size_t frames_in_flight() const noexcept;
  [[nodiscard]] const TransactionCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const FrameErrorCounters& frame_errors() const noexcept { return frame_errors_; }

 private:
  enum class SlotState : std::uint8_t { Free, Building, InFlight };
  struct Entry {
    DatagramOwner* owner = nullptr;
    std::uint32_t tag = 0;
    Command command = Command::NOP;
    std::uint32_t address = 0;
    std::uint16_t length = 0;
  };
  struct FrameSlot {
    SlotState state = SlotState::Free;
    std::uint8_t index = 0;
    std::uint64_t order = 0;  // queue order of Building frames
    core::TimePoint deadline{};
    std::array<std::uint8_t, kMaxFrameSize> bytes{};
    FrameBuilder builder{std::span<std::uint8_t>{}, kBroadcastMac, kBroadcastMac};
    std::array<Entry, kMaxDatagramsPerFrame> entries{};
    std::size_t count = 0;
  };

  FrameSlot* open_slot() noexcept;
  [[nodiscard]] bool index_in_use(std::uint8_t index) const noexcept;
  [[nodiscard]] static bool matches(const Entry& e, const Datagram& d, std::uint8_t index) noexcept;

  MacAddress source_;
  std::array<FrameSlot, kMaxFrames> slots_{};
  static constexpr std::size_t kNone = kMaxFrames;
  std::size_t building_ = kNone;  // the newest frame being built (queue() fills it first), if any
  std::array<std::span<const std::uint8_t>, kMaxFrames> outgoing_{};
  std::uint8_t next_index_ = 0;
  std::uint64_t next_order_ = 0;
  TransactionCounters counters_{};
  FrameErrorCounters frame_errors_{};
};

}  // namespace drivegate::ethercat
