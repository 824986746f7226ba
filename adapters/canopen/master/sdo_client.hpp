#pragma once
// SDO client (CiA 301 §7.2.4): expedited and segmented upload/download on any number of server
// channels, at most one transfer in flight per channel and a FIFO of waiting requests per channel
// (AKD part 1 §16 step 5: one outstanding request per drive). Block transfer is not offered by the
// reference drives and is not implemented.
//
// Channels are registered at construction time (node, channel number, COB-IDs); SD6 channels 2..4
// use the STÖBER COB-IDs (cob::sdo_rx(channel, node)). Requests carry up to kMaxData bytes, enough
// for identity strings and EDS-named objects; values of 1..4 bytes are the common case.
//
// Timeouts and retries: a request whose server does not answer within `timeout` is sent again from
// its initiate frame up to `retries` times; then (or on a timeout in the middle of a segmented
// transfer) the client sends abort 05040000h to the server and fails the request with that code.
// A toggle error aborts with 05030000h. A server abort fails the request with the server's code.
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
};

struct SdoClientCounters {
  std::uint64_t requests = 0;
  std::uint64_t completed = 0;
  std::uint64_t failed = 0;
  std::uint64_t aborts_received = 0;
  std::uint64_t timeouts = 0;
  std::uint64_t retries = 0;
  std::uint64_t unexpected = 0;  // well-formed but not expected now (dropped)
  std::uint64_t malformed = 0;   // wrong DLC, unknown specifier (dropped)
  std::uint64_t queue_full = 0;  // submit refused
  std::uint64_t tx_full = 0;     // TxQueue refused a frame (the timeout retries it)
};

class SdoClient {
 public:
  static constexpr std::size_t kMaxData = 64;        // bytes per request
  static constexpr std::size_t kQueueDepth = 32;     // waiting requests per channel

  SdoClient(std::span<const SdoChannelConfig> channels, SdoTiming timing);

  // Index of the channel for (node, channel number), or -1.
  [[nodiscard]] int channel_of(NodeId node, int channel = 1) const noexcept;

  // Upload (read). `expected_size` (1..4, or 0 = any) is the object's size: it is the length taken
  // from an expedited response without a size indication (SD6 42h: stoeber-sd6-canopen.md §6.4).
  SdoRequestId read(int channel, ObjectId object, std::uint8_t expected_size = 0) noexcept;
  // Download (write) of 1..4 bytes (expedited).
  SdoRequestId write(int channel, ObjectId object, std::uint32_t value, std::uint8_t size) noexcept;
  // Download of up to kMaxData bytes (expedited when <= 4, else segmented).
  SdoRequestId write_bytes(int channel, ObjectId object, std::span<const std::uint8_t> data) noexcept;

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

  // Number of requests queued or in flight on a channel.
  [[nodiscard]] std::size_t pending(int channel) const noexcept;

  // Engine interface (adapters/canopen/README.md).
  // True when the frame's COB-ID is one of this client's response COB-IDs (consumed).
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  void poll(core::TimePoint now, TxQueue& tx) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] const SdoClientCounters& counters() const noexcept { return counters_; }

 private:
  struct Impl;  // implementation detail (fixed-size storage, see sdo_client.cpp)
  // The implementation may replace these members; the public interface above is the contract.
  std::vector<SdoChannelConfig> channels_;
  SdoTiming timing_;
  SdoClientCounters counters_;
};

}  // namespace drivegate::canopen
