#pragma once
// SDO client (CiA 301 §7.2.4): expedited and segmented upload/download on any number of server
// channels, at most one transfer in flight per channel and a FIFO of waiting requests per channel
// (AKD part 1 §16 step 5: one outstanding request per drive). Block transfer is not offered by the
// reference drives and is not implemented.
//
// Channels are registered at construction time (node, channel number, COB-IDs); SD6 channels 2..4
// use the STÖBER COB-IDs (cob::sdo_rx(channel, node)). Requests carry up to kMaxData bytes in the
// client's own slots (the boot's writes, identity reads); read_into() and write_from() transfer
// larger objects (strings, domains) through the caller's buffer instead. An upload longer than its
// buffer is aborted with 05040005h (out of memory) and fails with that code. A caller that cancels
// a transfer with its own buffer in the middle of a segmented exchange gets its buffer back at
// once: the client aborts the transfer on the bus with 08000000h (general error).
//
// Timeouts and retries: a request whose server does not answer within `timeout` is sent again from
// its initiate frame up to `retries` times; then (or on a timeout in the middle of a segmented
// transfer: the server's segment state is unknown then, and a fresh initiate would meet a server
// still waiting for a segment) the client sends abort 05040000h to the server and fails the
// request with that code.
// A toggle error aborts with 05030000h; a segmented upload whose segments do not add up to the size
// the server announced aborts with 06070012h / 06070013h (too long / too short, like Lely's csdo).
// A server abort fails the request with the server's code.
//
// Unexpected frames (wrong DLC, unknown specifier, a response while idle, a response for another
// object, a segment with the wrong toggle outside the transfer rules) are counted and dropped.
//
// Nothing here allocates after construction.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen {

using SdoRequestId = std::uint32_t;  // 0 = none
inline constexpr SdoRequestId kNoSdoRequest = 0;

struct SdoChannelConfig {
  NodeId node = 0;
  int channel = 1;          // 1..4
  std::uint32_t rx_cob = 0; // client -> server (0: derived from node and channel)
  std::uint32_t tx_cob = 0; // server -> client (0: derived)
};

struct SdoTiming {
  core::Duration timeout = std::chrono::milliseconds(100);
  int retries = 2;
};

enum class SdoStatus : std::uint8_t { Queued, InFlight, Done, Failed, Unknown };

struct SdoResult {
  SdoStatus status = SdoStatus::Unknown;
  std::uint32_t abort_code = 0;  // when Failed (server's code, or 05040000h timeout, 05030000h toggle)
  std::uint32_t value = 0;       // uploads of 1..4 bytes: little-endian value (zero-extended)
  std::uint16_t size = 0;        // bytes received (uploads)
  bool size_indicated = true;    // false: an expedited upload without size (42h); `size` is then the
                                 // caller's expected size, or all 4 bytes when it gave none
};

struct SdoClientCounters {
  std::uint64_t requests = 0;
  std::uint64_t completed = 0;
  std::uint64_t failed = 0;
  std::uint64_t aborts_received = 0;
  std::uint64_t timeouts = 0;   // requests failed with 05040000h (retries exhausted, or mid-segment)
  std::uint64_t retries = 0;    // initiate frames sent again after a timeout
  std::uint64_t unexpected = 0;  // well-formed but not expected now (dropped)
  std::uint64_t malformed = 0;   // wrong DLC, unknown specifier (dropped)
  std::uint64_t queue_full = 0;  // submit refused
  std::uint64_t tx_full = 0;     // TxQueue refused a frame (the timeout retries it)
};

class SdoClient {
 public:
  static constexpr std::size_t kMaxData = 64;        // bytes per request in the client's slots
  static constexpr std::size_t kMaxBuffer = 0xFFFF;  // bytes per request in a caller's buffer
  static constexpr std::size_t kQueueDepth = 32;     // waiting requests per channel

  // Throws std::invalid_argument for a channel list that cannot work (node outside 1..127, channel
  // outside 1..4, a derived channel 2..4 COB-ID for a node above 31, COB-IDs that collide) or a
  // timing without a positive timeout.
  SdoClient(std::span<const SdoChannelConfig> channels, SdoTiming timing);

  // Index of the channel for (node, channel number), or -1.
  [[nodiscard]] int channel_of(NodeId node, int channel = 1) const noexcept;

  // Upload (read). `expected_size` (1..4, or 0 = any) is the object's size: it is the length taken
  // from an expedited response without a size indication (SD6 42h: stoeber-sd6-canopen.md §6.4).
  SdoRequestId read(int channel, ObjectId object, std::uint8_t expected_size = 0) noexcept;
  // Download (write) of 1..4 bytes (expedited).
  SdoRequestId write(int channel, ObjectId object, std::uint32_t value, std::uint8_t size) noexcept;
  // Upload into / download from the caller's buffer (up to kMaxBuffer bytes), which stays in use
  // until take() or cancel(). `expected_size` as for read().
  SdoRequestId read_into(int channel, ObjectId object, std::span<std::uint8_t> into,
                         std::uint8_t expected_size = 0) noexcept;
  SdoRequestId write_from(int channel, ObjectId object, std::span<const std::uint8_t> data) noexcept;

  // Status of a request. Done/Failed are reported until take() or cancel().
  [[nodiscard]] SdoResult result(SdoRequestId id) const noexcept;
  // Bytes of a finished upload (valid until take()/cancel()).
  [[nodiscard]] std::span<const std::uint8_t> data(SdoRequestId id) const noexcept;
  // Forget a finished request (frees its slot); returns its final result.
  SdoResult take(SdoRequestId id) noexcept;
  // The caller no longer wants `id`: a queued request is dropped; one in flight finishes on the
  // wire but its result is discarded. Unknown ids are ignored.
  void cancel(SdoRequestId id) noexcept;
  // Drop every request of a channel (node lost or rebooted): they report Unknown afterwards; a
  // transfer in flight is not aborted on the wire.
  void reset_channel(int channel) noexcept;

  // Number of requests queued or in flight on a channel (a cancelled transfer still on the wire
  // counts: the channel is busy until it ends).
  [[nodiscard]] std::size_t pending(int channel) const noexcept;

  // Engine interface (adapters/canopen/README.md).
  // True when the frame's COB-ID is one of this client's response COB-IDs (consumed).
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  // Queues at most `max_frames` frames; what does not fit stays due (next_deadline() keeps
  // saying so) and goes out, in order, at a later poll().
  void poll(core::TimePoint now, TxQueue& tx, std::size_t max_frames = SIZE_MAX) noexcept;
  // TimePoint::min() while a frame waits for poll() (a request submitted, a response that asks for
  // the next segment, an abort), else the earliest timeout, else TimePoint::max().
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] const SdoClientCounters& counters() const noexcept { return counters_; }

 private:
  // One request from submit to take(): what to transfer and, once finished, the outcome. Slots
  // are recycled; `generation` makes a stale id (taken, cancelled, reset) report Unknown.
  enum class SlotState : std::uint8_t { Free, Queued, InFlight, Cancelled, Done, Failed };
  enum class Kind : std::uint8_t { Upload, Download };
  struct Slot {
    SlotState state = SlotState::Free;
    Kind kind = Kind::Upload;
    std::uint16_t generation = 0;
    ObjectId object{};
    std::uint8_t expected_size = 0;  // uploads: length of a 42h response (0 = all four bytes)
    std::uint16_t size = 0;          // downloads: bytes to send; uploads: bytes received
    bool size_indicated = true;      // uploads: the server said how many bytes
    std::uint32_t abort_code = 0;
    std::array<std::uint8_t, kMaxData> data{};
    // The caller's buffer (read_into / write_from), else null and `data` is used.
    std::uint8_t* into = nullptr;
    const std::uint8_t* from = nullptr;
    std::uint16_t capacity = 0;  // of `into`

    [[nodiscard]] bool external() const noexcept { return into != nullptr || from != nullptr; }
    [[nodiscard]] std::uint8_t* sink() noexcept { return into != nullptr ? into : data.data(); }
    [[nodiscard]] const std::uint8_t* source() const noexcept {
      return from != nullptr ? from : into != nullptr ? into : data.data();
    }
    [[nodiscard]] std::size_t room() const noexcept { return into != nullptr ? capacity : kMaxData; }
  };
  // Where the transfer in flight stands: which response the client waits for.
  enum class Phase : std::uint8_t { Idle, Initiate, Segment };
  // Slots per channel: a full FIFO, the transfer in flight and as many finished results waiting
  // for take(). When they are all in use, submit is refused (counted as queue_full).
  static constexpr std::size_t kSlotsPerChannel = 2 * kQueueDepth + 1;
  struct Channel {
    SdoChannelConfig config{};
    std::array<Slot, kSlotsPerChannel> slots{};
    std::array<std::uint8_t, kQueueDepth> fifo{};  // slot numbers, oldest at fifo_head
    std::size_t fifo_head = 0;
    std::size_t fifo_size = 0;
    // The transfer in flight.
    Phase phase = Phase::Idle;
    std::uint8_t active = 0;        // slot number, valid when phase != Idle
    bool toggle = false;            // toggle bit of the segment sent / requested last
    bool last_sent = false;         // segmented download: the segment sent last had c = 1
    std::uint16_t offset = 0;       // bytes sent (download) or received (upload) so far
    std::uint32_t total = 0;        // segmented upload: size the server indicated ...
    bool total_indicated = false;   // ... if it did (s = 1)
    int retries_left = 0;
    core::TimePoint deadline = core::TimePoint::max();
    bool frame_due = false;         // `frame` is to be sent by the next poll()
    SdoBytes frame{};
    bool abort_due = false;         // `abort_frame` is to be sent by the next poll()
    SdoBytes abort_frame{};
  };

  SdoRequestId submit(int channel, Kind kind, ObjectId object, std::uint8_t expected_size,
                      std::span<const std::uint8_t> data) noexcept;
  // The slot just queued takes the caller's buffer.
  SdoRequestId attach(SdoRequestId id, std::uint8_t* into, const std::uint8_t* from, std::size_t size) noexcept;
  [[nodiscard]] const Slot* find(SdoRequestId id) const noexcept;
  [[nodiscard]] Slot* find(SdoRequestId id) noexcept;
  void start(Channel& ch, core::TimePoint now, TxQueue& tx) noexcept;
  [[nodiscard]] static SdoBytes initiate_frame(const Slot& slot) noexcept;
  void send(Channel& ch, const SdoBytes& bytes, TxQueue& tx) noexcept;
  void on_response(Channel& ch, const SdoMessage& m) noexcept;
  void on_upload(Channel& ch, Slot& slot, const SdoMessage& m) noexcept;
  void on_download(Channel& ch, Slot& slot, const SdoMessage& m) noexcept;
  void next_download_segment(Channel& ch, const Slot& slot) noexcept;
  void finish(Channel& ch, Slot& slot, SlotState state, std::uint32_t abort_code) noexcept;
  void fail_and_abort(Channel& ch, Slot& slot, std::uint32_t abort_code) noexcept;

  std::vector<Channel> channels_;
  std::array<std::int16_t, kMaxStandardId + 1> by_tx_cob_{};  // response COB-ID -> channel, -1 = none
  SdoTiming timing_;
  SdoClientCounters counters_;
};

}  // namespace drivegate::canopen
