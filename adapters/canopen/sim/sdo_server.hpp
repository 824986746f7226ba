#pragma once
// SDO server of a simulated slave (CiA 301 §7.2.4): one instance per server channel, answering
// expedited and segmented uploads and downloads from an SdoBackend (the slave's object store).
// Block transfer is not offered, like on the reference drives (AKD part 1 §10.1, SD6 §6.3): a
// block specifier is answered like an unknown one, with abort 05040001h.
//
// Protocol errors are answered the CiA 301 way: a wrong toggle aborts with 05030000h, an unknown
// or block specifier and a segment without an initiate with 05040001h, a segmented transfer idle
// for longer than `timeout` with 05040000h. Frames of the wrong length cannot be answered reliably
// and are counted and dropped. A new initiate while a segmented transfer is open replaces it: that
// is what a client that timed out retries with (master/sdo_client.hpp).
//
// Persona and fault injection (the tests and the simulated drives of other vendors use them):
// - upload_without_size: answer uploads of <= 4 bytes with 42h, size not indicated, as the SD6 may
//   (stoeber-sd6-canopen.md §6.4);
// - inject_abort(): abort the next request for one object with a given code;
// - set_silent(): receive nothing and answer nothing while set (a server that has gone away).
//
// Responses are produced in on_frame() and handed out by poll(), like the master engines
// (adapters/canopen/README.md). Nothing here allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"
#include "core/clock.hpp"

namespace drivegate::canopen::sim {

struct SdoReadResult {
  std::uint32_t abort_code = 0;  // 0 = ok
  std::size_t size = 0;          // bytes of the object; more than out.size() fails with 05040005h
};

// The slave's object dictionary as the SDO server sees it. Values are little-endian bytes.
class SdoBackend {
 public:
  // Read an object's bytes (little-endian) into out; returns abort code (0 = ok) and size.
  virtual SdoReadResult sdo_read(ObjectId object, std::span<std::uint8_t> out) noexcept = 0;
  // Write an object; returns the abort code (0 = ok).
  virtual std::uint32_t sdo_write(ObjectId object, std::span<const std::uint8_t> data) noexcept = 0;

 protected:
  ~SdoBackend() = default;
};

struct SdoServerConfig {
  std::uint32_t rx_cob = 0;  // client -> server (requests), e.g. 600h + node
  std::uint32_t tx_cob = 0;  // server -> client (responses), e.g. 580h + node
  core::Duration timeout = std::chrono::milliseconds(1000);  // idle segmented transfer is aborted
  bool upload_without_size = false;                          // 42h persona (SD6 §6.4)
};

struct SdoServerCounters {
  std::uint64_t requests = 0;          // initiate requests received
  std::uint64_t completed = 0;         // transfers answered successfully to the end
  std::uint64_t aborts_sent = 0;       // every abort frame the server produced
  std::uint64_t aborts_received = 0;   // the client aborted (a transfer in progress, or none)
  std::uint64_t toggle_errors = 0;     // aborted with 05030000h
  std::uint64_t unknown_command = 0;   // unknown or block specifier (aborted with 05040001h)
  std::uint64_t unexpected = 0;        // a segment without an initiate (aborted with 05040001h)
  std::uint64_t replaced = 0;          // an initiate arrived while a segmented transfer was open
  std::uint64_t timeouts = 0;          // idle segmented transfers aborted with 05040000h
  std::uint64_t injected = 0;          // requests aborted by inject_abort()
  std::uint64_t malformed = 0;         // wrong DLC or RTR (dropped, no answer)
  std::uint64_t ignored_silent = 0;    // frames received while silent
  std::uint64_t tx_full = 0;           // a response lost (outbox or TxQueue full)
};

class SdoServer {
 public:
  static constexpr std::size_t kBufferSize = 4096;  // bytes of one segmented transfer (a domain of 4 KiB)

  SdoServer(SdoServerConfig config, SdoBackend& backend) noexcept;

  // True when the frame's COB-ID is this server's request COB-ID (consumed).
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  void poll(core::TimePoint now, TxQueue& tx) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  // Drop a transfer in progress without a word (NMT reset communication, power loss).
  void reset() noexcept;

  void set_upload_without_size(bool on) noexcept { config_.upload_without_size = on; }
  // The next initiate for `object` (upload or download) is answered with abort `code` (replaces an
  // earlier injection that has not fired yet).
  void inject_abort(ObjectId object, std::uint32_t code) noexcept;
  // While silent, received frames are dropped and nothing is sent; an open transfer is forgotten.
  void set_silent(bool on) noexcept;

  [[nodiscard]] bool transfer_open() const noexcept { return state_ != State::Idle; }
  [[nodiscard]] const SdoServerConfig& config() const noexcept { return config_; }
  [[nodiscard]] const SdoServerCounters& counters() const noexcept { return counters_; }

 private:
  enum class State : std::uint8_t { Idle, Download, Upload };

  void on_request(const SdoMessage& m, core::TimePoint now) noexcept;
  void initiate_upload(ObjectId object, core::TimePoint now) noexcept;
  void initiate_download(const SdoMessage& m, core::TimePoint now) noexcept;
  void download_segment(const SdoMessage& m, core::TimePoint now) noexcept;
  void upload_segment(const SdoMessage& m, core::TimePoint now) noexcept;
  bool take_injected(ObjectId object) noexcept;
  void respond(const SdoBytes& bytes) noexcept;
  void abort(ObjectId object, std::uint32_t code) noexcept;

  SdoServerConfig config_;
  SdoBackend& backend_;
  SdoServerCounters counters_;
  FrameQueue<4> outbox_;  // responses produced by on_frame(), sent by poll()
  bool silent_ = false;
  bool injection_armed_ = false;
  ObjectId injected_object_{};
  std::uint32_t injected_code_ = 0;

  // The segmented transfer in progress.
  State state_ = State::Idle;
  ObjectId object_{};
  bool toggle_ = false;                 // toggle expected in the next segment request
  bool size_indicated_ = false;         // download: the client announced `size_`
  std::size_t size_ = 0;                // download: announced size; upload: object size
  std::size_t offset_ = 0;              // bytes received (download) or sent (upload)
  core::TimePoint deadline_ = core::TimePoint::max();
  std::array<std::uint8_t, kBufferSize> buffer_{};
};

}  // namespace drivegate::canopen::sim
