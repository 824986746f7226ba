#pragma once
// The controller's cyclic data of one AR, RT class 1, sans-I/O [IEC 61158-6-10 §4.7: the cyclic
// provider (PPM) and consumer (CPM) protocol machines]: frames and the time go in, frames come out
// into the caller's buffer (DESIGN.md §2 rule 1). Nothing here allocates after construction.
//
//   RtProvider (the output IOCR): owns the output frame (header with the 802.1Q priority tag 6,
//     VID 0, and the C_SDU laid out by compute_csdu_layout); the application writes each
//     submodule's data, its IOPS and the IOCS of the input submodules through the accessors, and
//     poll() emits the frame on the exact schedule
//         t(n) = start + (phase - 1) × send clock + n × period,
//         send clock = SendClockFactor × 31.25 µs, period = send clock × ReductionRatio,
//     with the cycle counter of t(n) (cycle_counter_at: it steps by SendClockFactor ×
//     ReductionRatio per frame) and DataStatus primary, DataValid, RUN or STOP, station ok. A
//     poll() later than the next slot sends once, for the latest slot due, and counts the slots
//     skipped (`missed_slots`): a late frame is never sent twice and the schedule never drifts.
//   RtConsumer (the input IOCR): on_frame() takes the frames with its FrameID from the device's
//     MAC and checks them (check_input_frame): frame errors (truncated, TransferStatus, a repeated
//     or old cycle counter) are dropped and counted; a frame that passes the cycle counter check
//     with DataValid and not Ignore is a valid frame: it restarts the data-hold watchdog, and its
//     C_SDU (data, IOPS per input submodule, IOCS per output submodule) and DataStatus become the
//     current values (ProviderState STOP and StationProblemIndicator are reported; a backup
//     provider's frame restarts the watchdog but its data is not taken). No valid frame within DataHoldFactor × period of arm() or of the last valid
//     frame: the consumer goes to Timeout once, with a text (the bus turns it into Lost), and
//     stays there: frames that come back are counted, not taken, until arm() (a new AR).
//     [IEC 61158-6-10 §4.7.2.1.2; the DHT is retriggered only by frames that may be used. A frame
//     with DataValid clear or Ignore set passes the cycle counter check but neither retriggers the
//     DHT nor replaces the data.]
//
// The same engines run the device's end of the AR (the simulator) with RtSide::Device: its
// provider sends the input CR (device -> controller: the input data with their IOPS, the IOCS of
// the output data) and its consumer takes the output CR from the controller's MAC.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/ethernet.hpp"
#include "adapters/profinet/wire/rt.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::profinet {

// The submodules one AR's IOCRs can carry (the C_SDU bounds them anyway: 1440 octets).
inline constexpr std::size_t kMaxRtSubmodules = 64;
// One SendClockFactor unit: 31.25 µs [IEC 61158-6-10, SendClockFactor].
inline constexpr core::Duration kSendClockUnit{31250};

// One IOCR as the Connect set it up (IOCRBlockReq). `submodules` lists the AR's submodules in
// the Connect's order; both CRs of an AR use the same list.
struct RtIocrConfig {
  std::uint16_t frame_id = frame_id::kRtClass1First;
  MacAddress controller_mac{};  // the output CR's source, the input CR's destination
  MacAddress device_mac{};
  std::uint16_t send_clock_factor = 32;  // 1..128 (32: 1 ms)
  std::uint16_t reduction_ratio = 1;     // 1..512, a power of two (RT class 1)
  std::uint16_t phase = 1;               // 1..reduction_ratio
  std::uint16_t data_hold_factor = 3;    // 1..7680 (the consumer's watchdog)
  std::span<const IoSubmodule> submodules{};
};

enum class RtConfigError : std::uint8_t {
  None,
  BadFrameId,         // not an RT class 1 FrameID (8000h-FBFFh)
  BadSendClock,       // SendClockFactor outside 1..128
  BadReductionRatio,  // not a power of two in 1..512
  BadPhase,           // outside 1..ReductionRatio
  BadDataHold,        // DataHoldFactor outside 1..7680
  TooManySubmodules,  // more than kMaxRtSubmodules
  DataTooLong,        // one CR's IO data needs more than 1440 octets (compute_csdu_layout)
  BadSubmodule,       // a submodule has a data length for a direction its kind does not have
};
std::string_view to_string(RtConfigError e) noexcept;
RtConfigError validate(const RtIocrConfig& c) noexcept;
// SendClockFactor × ReductionRatio × 31.25 µs.
constexpr core::Duration rt_period(const RtIocrConfig& c) noexcept {
  return kSendClockUnit * c.send_clock_factor * c.reduction_ratio;
}
constexpr core::Duration rt_data_hold_time(const RtIocrConfig& c) noexcept { return rt_period(c) * c.data_hold_factor; }

// Which end of the AR an engine runs: the controller provides the output CR and consumes the
// input CR; the device the other way round.
enum class RtSide : std::uint8_t { Controller, Device };

struct RtProviderCounters {
  std::uint64_t frames_sent = 0;
  std::uint64_t missed_slots = 0;   // slots that passed without a poll() (not sent late)
  std::uint64_t tx_too_small = 0;   // poll() was given a buffer shorter than the frame (slot lost)
};

class RtProvider {
 public:
  // Builds the frame of the CR `side` provides (the controller: the output CR); an invalid config
  // leaves the provider inert (error()).
  explicit RtProvider(const RtIocrConfig& config, RtSide side = RtSide::Controller) noexcept;

  [[nodiscard]] RtConfigError error() const noexcept { return error_; }
  [[nodiscard]] bool ok() const noexcept { return error_ == RtConfigError::None; }
  [[nodiscard]] core::Duration period() const noexcept { return period_; }
  [[nodiscard]] std::size_t frame_size() const noexcept { return frame_size_; }

  // The application's side, any time between polls. Index i names config.submodules[i].
  // The data submodule i provides in this CR (the controller: its output data; empty when none).
  [[nodiscard]] std::span<std::uint8_t> data(std::size_t i) noexcept;
  // IOPS of the data submodule i provides in this CR / IOCS for the data it consumes from the
  // other one (iox_status::); false when submodule i has no such object in this CR. IOPS start
  // bad (by controller, or by device on the device's side), IOCS good.
  bool set_iops(std::size_t i, std::uint8_t iops) noexcept;
  bool set_iocs(std::size_t i, std::uint8_t iocs) noexcept;
  // DataStatus ProviderState RUN (true, the start) or STOP.
  void set_provider_run(bool run) noexcept { run_ = run; }
  [[nodiscard]] std::span<const IoPlacement> placements() const noexcept {
    return std::span(placements_).first(submodule_count_);
  }

  // Starts the schedule: the first frame is due at start + (phase - 1) × send clock.
  void start(core::TimePoint start) noexcept;
  void stop() noexcept { running_ = false; }
  [[nodiscard]] bool running() const noexcept { return running_; }

  // Writes the frame into `out` when a slot is due and returns its length, else 0.
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept;
  // The next slot; TimePoint::max() while stopped.
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;
  [[nodiscard]] const RtProviderCounters& counters() const noexcept { return counters_; }

 private:
  RtConfigError error_ = RtConfigError::None;
  CsduLayout layout_{};
  std::size_t submodule_count_ = 0;
  std::array<IoPlacement, kMaxRtSubmodules> placements_{};
  core::Duration period_{};
  core::Duration offset_{};  // (phase - 1) × send clock
  std::size_t pdu_offset_ = 0;
  std::size_t frame_size_ = 0;
  std::array<std::uint8_t, kMaxFrameSize> frame_{};  // header, C_SDU, status (written per poll)
  bool run_ = true;
  bool running_ = false;
  core::TimePoint next_{};
  RtProviderCounters counters_{};
};

enum class RtConsumerState : std::uint8_t {
  Idle,     // not armed: frames are counted (inactive), not taken
  Waiting,  // armed, no valid frame yet
  Running,  // valid frames arrive within the data-hold time
  Timeout,  // the data-hold time passed without a valid frame (reason()); until arm()
};
std::string_view to_string(RtConsumerState s) noexcept;

struct RtConsumerCounters {
  std::uint64_t frames = 0;          // valid frames taken
  std::uint64_t wrong_frame_id = 0;  // an RT class 1 frame with another FrameID (not taken)
  std::uint64_t wrong_source = 0;    // this FrameID from another MAC than the device's
  std::uint64_t malformed = 0;       // not a PROFINET Ethernet frame (decode_ethernet failed)
  std::uint64_t truncated = 0, transfer_error = 0, repeated_cycle = 0, old_cycle = 0;
  std::uint64_t ignore = 0, data_invalid = 0;  // pass the cycle check, not taken
  std::uint64_t backup = 0;          // State backup: not taken
  std::uint64_t provider_stop = 0;   // taken (valid data, the device application stopped)
  std::uint64_t station_problem = 0; // taken frames with the StationProblemIndicator set
  std::uint64_t inactive = 0;        // this CR's frames while Idle or in Timeout
  std::uint64_t timeouts = 0;        // data-hold watchdog expiries
};

class RtConsumer {
 public:
  // Consumes the CR the other side provides (the controller: the input CR from the device's MAC).
  explicit RtConsumer(const RtIocrConfig& config, RtSide side = RtSide::Controller) noexcept;

  [[nodiscard]] RtConfigError error() const noexcept { return error_; }
  [[nodiscard]] bool ok() const noexcept { return error_ == RtConfigError::None; }
  [[nodiscard]] core::Duration data_hold_time() const noexcept { return data_hold_; }

  // Starts (or, after Timeout, restarts for a new AR) the consumer: the first valid frame is
  // due within the data-hold time from `now`; the current data is cleared (IOPS bad).
  void arm(core::TimePoint now) noexcept;
  void disarm() noexcept { state_ = RtConsumerState::Idle; }

  // True when the frame had this CR's FrameID (taken, or dropped and counted); false for other
  // traffic (another CR's FrameID is counted as wrong_frame_id, a malformed frame as malformed).
  bool on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  // Runs the watchdog; true when it has just expired (the state is now Timeout).
  bool poll(core::TimePoint now) noexcept;
  // When the watchdog expires; TimePoint::max() unless Waiting or Running.
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] RtConsumerState state() const noexcept { return state_; }
  [[nodiscard]] std::string_view reason() const noexcept { return reason_.view(); }
  // The last valid frame's values (zeros and bad IOPS before the first one).
  [[nodiscard]] std::span<const std::uint8_t> data(std::size_t i) const noexcept;
  // The provider's status of the data it sends for submodule i (the controller: of its input data).
  [[nodiscard]] std::uint8_t iops(std::size_t i) const noexcept;
  // The provider's status of the data we send for submodule i (the controller: the device's for
  // its output data).
  [[nodiscard]] std::uint8_t iocs(std::size_t i) const noexcept;
  [[nodiscard]] bool all_iops_good() const noexcept;
  [[nodiscard]] const ApduStatus& status() const noexcept { return status_; }
  [[nodiscard]] bool provider_run() const noexcept { return status_.provider_run(); }
  [[nodiscard]] bool station_problem() const noexcept { return status_.station_problem(); }
  [[nodiscard]] std::span<const IoPlacement> placements() const noexcept {
    return std::span(placements_).first(submodule_count_);
  }
  [[nodiscard]] const RtConsumerCounters& counters() const noexcept { return counters_; }

 private:
  void expire(core::TimePoint now) noexcept;

  RtConfigError error_ = RtConfigError::None;
  RtSide side_ = RtSide::Controller;
  std::uint16_t frame_id_ = 0;
  MacAddress peer_mac_{};  // the provider's
  CsduLayout layout_{};
  std::size_t submodule_count_ = 0;
  std::array<IoPlacement, kMaxRtSubmodules> placements_{};
  core::Duration data_hold_{};
  RtConsumerState state_ = RtConsumerState::Idle;
  core::TimePoint last_valid_{};
  bool has_last_ = false;
  std::uint16_t last_cycle_ = 0;
  ApduStatus status_{};
  std::array<std::uint8_t, kMaxCsduLength> c_sdu_{};
  RtConsumerCounters counters_{};
  core::FixedString<160> reason_{};
};

}  // namespace drivegate::profinet
