#pragma once
// The device side of one AR's alarm CR for the simulator, sans-I/O like the controller's engines
// [IEC 61158-6-10: ALPMI, the alarm initiator, over APMS/APMR per priority
// (controller/rta_endpoint.hpp)]:
//
//   send() queues an alarm (kQueueDepth per priority; the AlarmSpecifier's sequence number is
//   counted here, 0..7FFh per priority). One alarm per priority is on its way at a time: its
//   DATA-RTA-PDU with the AlarmNotification goes out, is retransmitted after RTATimeoutFactor ×
//   100 ms until the controller's ACK (or a DATA acknowledging it) comes, and the alarm is done
//   when the controller's AlarmAck (a DATA-RTA-PDU, acknowledged here) echoes its type, API,
//   slot, subslot and sequence; then the next queued alarm of that priority goes out.
//   No ACK after 1 + RTARetries frames: Aborted, with an ERR-RTA-PDU (RTA protocol error "AR
//   alarm-send.cnf(-)", CF 81 FD 08). An ERR from the controller: Aborted. abort() sends an ERR
//   with the caller's PNIOStatus (fault injection). Other frames are counted and dropped.
//
// Nothing allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/controller/rta_endpoint.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::profinet {

struct AlarmSenderConfig {
  MacAddress device_mac{};
  MacAddress controller_mac{};
  AlarmCrBlockReq alarm_cr{};          // the Connect's: the controller's reference, timeout, retries, tags
  std::uint16_t device_reference = 1;  // this device's LocalAlarmReference (AlarmCRBlockRes)
};

enum class AlarmSenderState : std::uint8_t { Closed, Open, Aborted };
std::string_view to_string(AlarmSenderState s) noexcept;

struct AlarmSenderCounters {
  std::uint64_t queued = 0;
  std::uint64_t refused = 0;          // send() refused: queue full, data too long, not open
  std::uint64_t acknowledged = 0;     // alarms whose AlarmAck came with PNIOStatus OK
  std::uint64_t refused_by_controller = 0;  // AlarmAcks with another PNIOStatus (the alarm is done too)
  std::uint64_t unmatched_acks = 0;   // AlarmAcks that do not echo the alarm on its way (taken, ignored)
  std::uint64_t wrong_source = 0, wrong_endpoint = 0, malformed = 0, unexpected_block = 0, inactive = 0;
};

class AlarmSender {
 public:
  static constexpr std::size_t kQueueDepth = 4;       // per priority, the alarm on its way included
  static constexpr std::size_t kMaxAlarmData = 200;   // the smallest MaxAlarmDataLength

  explicit AlarmSender(const AlarmSenderConfig& config) noexcept;

  [[nodiscard]] AlarmCrError error() const noexcept { return error_; }
  void open() noexcept;
  void close() noexcept;
  [[nodiscard]] AlarmSenderState state() const noexcept { return state_; }
  [[nodiscard]] std::string_view reason() const noexcept { return reason_.view(); }

  // Queues `n` (its priority picks the channel; the user data is copied, at most kMaxAlarmData
  // octets; the specifier's sequence number is replaced). False when refused.
  bool send(const AlarmNotification& n) noexcept;
  // Alarms of priority `p` queued or on their way.
  [[nodiscard]] std::size_t pending(AlarmPriority p) const noexcept { return side(p).count; }
  // Sends an ERR-RTA-PDU with `status` on the low priority and ends (Aborted).
  void abort(const RtaPnioStatus& status) noexcept;
  // The PNIOStatus of the last AlarmAck of priority `p`.
  [[nodiscard]] const RtaPnioStatus& last_ack_status(AlarmPriority p) const noexcept { return side(p).last_status; }

  bool on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] const AlarmSenderCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const RtaCounters& rta_counters(AlarmPriority p) const noexcept { return side(p).rta.counters(); }

 private:
  struct Alarm {
    AlarmNotification n{};  // user_data points nowhere: `data` holds it
    std::size_t length = 0;
    std::array<std::uint8_t, kMaxAlarmData> data{};
  };
  struct Side {
    explicit Side(const RtaEndpointConfig& c) noexcept : rta(c) {}
    RtaEndpoint rta;
    std::array<Alarm, kQueueDepth> queue{};  // queue[head] is the one on its way while `sent`
    std::size_t head = 0;
    std::size_t count = 0;
    bool sent = false;            // queue[head] went out and waits for its AlarmAck
    std::uint16_t sequence = 0;   // the next AlarmSpecifier sequence number
    RtaPnioStatus last_status{};
  };

  Side& side(AlarmPriority p) noexcept { return p == AlarmPriority::High ? high_ : low_; }
  const Side& side(AlarmPriority p) const noexcept { return p == AlarmPriority::High ? high_ : low_; }
  void on_data(Side& s, std::span<const std::uint8_t> block) noexcept;
  bool start_next(Side& s) noexcept;

  AlarmSenderConfig config_;
  AlarmCrError error_;
  AlarmSenderState state_ = AlarmSenderState::Closed;
  Side high_;
  Side low_;
  AlarmSenderCounters counters_{};
  core::FixedString<300> reason_{};
};

}  // namespace drivegate::profinet
