#pragma once
// The controller's side of one AR's alarm CR, RT class 1 over raw Ethernet, sans-I/O
// [IEC 61158-6-10: the alarm protocol machines; ALPMR, the alarm receiver, over APMS/APMR per
// priority (controller/rta_endpoint.hpp), FrameID FC01h high / FE01h low]:
//
//   A DATA-RTA-PDU with an AlarmNotification (0001h in FC01h, 0002h in FE01h) in sequence is
//   taken: the transport ACK goes out at the next poll(), the listener gets the alarm with one
//   line of text (alarm_text()), and the AlarmAck (8001h/8002h, the notification's fields echoed,
//   PNIOStatus OK) goes out as our own DATA-RTA-PDU, retransmitted after RTATimeoutFactor × 100 ms
//   up to RTARetries times (the AlarmCR block's values). A retransmitted notification (our ACK was
//   lost) is acknowledged again and not handed up twice. Each priority runs on its own: a high
//   alarm is never held up behind a low one.
//   The AlarmAcks wait in a fixed queue of kAckQueueDepth per priority; a notification that finds
//   it full is neither acknowledged nor handed up (counted): the device sends it again.
//   An ERR-RTA-PDU from the device, or an AlarmAck the device never acknowledges, aborts the alarm
//   CR: state Aborted with a reason() (the bus ends the AR). In the second case an ERR-RTA-PDU
//   (RTA protocol error "AR alarm-ack-send.cnf(-)", CF 81 FD 09) goes to the device first.
//   Dropped and counted: frames from another MAC, other alarm endpoints (AlarmDst/SrcEndpoint
//   not the AR's alarm references), RTA-PDUs or blocks that do not decode, a notification of the
//   other priority's block type, other blocks (an AlarmAck: the controller sends no alarms), and
//   alarm frames while not open.
//
// Nothing allocates after construction; the listener is called from on_frame().
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/controller/rta_endpoint.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::profinet {

struct AlarmChannelConfig {
  MacAddress controller_mac{};
  MacAddress device_mac{};
  // The Connect's AlarmCRBlockReq: the controller's LocalAlarmReference, RTATimeoutFactor,
  // RTARetries and the tag headers of both priorities.
  AlarmCrBlockReq alarm_cr{};
  std::uint16_t device_reference = 0;  // AlarmCRBlockRes LocalAlarmReference
};

// One taken alarm: the notification's views are valid during the call only.
struct AlarmEvent {
  AlarmNotification notification{};
  std::string_view text{};  // alarm_text(); valid during the call only
};

class AlarmListener {
 public:
  virtual void on_alarm(const AlarmEvent& event) noexcept = 0;

 protected:
  AlarmListener() = default;
  AlarmListener(const AlarmListener&) = default;
  AlarmListener& operator=(const AlarmListener&) = default;
  ~AlarmListener() = default;
};

// One line for a person: "alarm high: Diagnosis (0x0001), API 0x00000000 slot 1 subslot 0x0001, module
// 0x00000010 submodule 0x00000011, sequence 5, submodule has diagnosis, AR has diagnosis; channel
// 3 (input) overtemperature, appears, fault". Written into `out` (cut when it does not fit).
std::string_view alarm_text(const AlarmNotification& n, std::span<char> out) noexcept;

enum class AlarmChannelState : std::uint8_t {
  Closed,   // not opened for an AR (or closed): alarm frames counted as inactive
  Open,     // taking alarms
  Aborted,  // ERR received or an AlarmAck not acknowledged: reason(); until open() for a new AR
};
std::string_view to_string(AlarmChannelState s) noexcept;

struct AlarmChannelCounters {
  std::uint64_t alarms = 0;            // notifications taken and handed to the listener
  std::uint64_t acks_confirmed = 0;    // AlarmAcks the device acknowledged
  std::uint64_t queue_full = 0;        // a notification that found the AlarmAck queue full
  std::uint64_t wrong_source = 0;      // an alarm frame from another MAC
  std::uint64_t wrong_endpoint = 0;    // AlarmDst/SrcEndpoint not this AR's alarm references
  std::uint64_t malformed = 0;         // RTA-PDU or AlarmNotification that does not decode
  std::uint64_t wrong_priority = 0;    // the other priority's notification block in this FrameID
  std::uint64_t unexpected_block = 0;  // a DATA with another block (e.g. an AlarmAck)
  std::uint64_t bad_channel_diagnosis = 0;  // channel diagnosis data that does not decode (alarm taken)
  std::uint64_t inactive = 0;          // alarm frames while Closed or Aborted
};

class AlarmChannel {
 public:
  static constexpr std::size_t kAckQueueDepth = 4;  // per priority

  // An invalid AlarmCR (RTATimeoutFactor, RTARetries) leaves the channel inert (error()).
  explicit AlarmChannel(const AlarmChannelConfig& config, AlarmListener* listener = nullptr) noexcept;

  [[nodiscard]] AlarmCrError error() const noexcept { return error_; }
  [[nodiscard]] bool ok() const noexcept { return error_ == AlarmCrError::None; }

  // Starts taking alarms for a new AR (sequence numbers from the start, queues empty).
  void open() noexcept;
  void close() noexcept;
  [[nodiscard]] AlarmChannelState state() const noexcept { return state_; }
  [[nodiscard]] std::string_view reason() const noexcept { return reason_.view(); }

  // True when the frame was an alarm frame (taken, or dropped and counted); false for other traffic.
  bool on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  // At most one frame into `out` (high priority first); call until it returns 0.
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] const AlarmChannelCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const RtaCounters& rta_counters(AlarmPriority p) const noexcept { return side(p).rta.counters(); }

 private:
  struct Side {
    explicit Side(const RtaEndpointConfig& c) noexcept : rta(c) {}
    RtaEndpoint rta;
    std::array<AlarmAck, kAckQueueDepth> queue{};
    std::size_t head = 0;
    std::size_t count = 0;
    AlarmAck in_flight{};  // the AlarmAck the RTA endpoint is sending
  };

  Side& side(AlarmPriority p) noexcept { return p == AlarmPriority::High ? high_ : low_; }
  const Side& side(AlarmPriority p) const noexcept { return p == AlarmPriority::High ? high_ : low_; }
  void on_notification(Side& s, std::span<const std::uint8_t> block) noexcept;
  bool start_next_ack(Side& s) noexcept;
  void abort_on_timeout(Side& s) noexcept;
  void abort_by_device(Side& s, const RtaPnioStatus& status) noexcept;

  AlarmChannelConfig config_;
  AlarmListener* listener_;
  AlarmCrError error_;
  AlarmChannelState state_ = AlarmChannelState::Closed;
  Side high_;
  Side low_;
  AlarmChannelCounters counters_{};
  core::FixedString<300> reason_{};
  std::array<char, 512> text_{};
};

}  // namespace drivegate::profinet
