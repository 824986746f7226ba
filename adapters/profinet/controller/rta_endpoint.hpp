#pragma once
// One priority of an alarm CR's acyclic real-time transport, either side, sans-I/O: the APMS
// (sending DATA-RTA-PDUs, one at a time, retransmitted until acknowledged) and the APMR (taking
// DATA-RTA-PDUs in sequence, acknowledging them, re-acknowledging duplicates) of
// [IEC 61158-6-10, the alarm protocol machines APMS/APMR; RT class 1 over raw Ethernet, FrameID
// FC01h high / FE01h low]. The alarm engines above it (controller/alarm_channel: the controller's
// ALPMR; sim/alarm_sender: the device's ALPMI) decide what the DATA carries.
//
// Sequence numbers, window size 1 [cross-checked with p-net's pf_alarm.c, a device stack that
// works with the controllers in the field]:
//   APMS  SendSeqNum of the DATA in flight, FFFFh for the first, then 0, 1, ... 7FFFh, 0 (each
//         time the DATA in flight is acknowledged: an ACK-RTA-PDU or a DATA-RTA-PDU whose
//         AckSeqNum is that SendSeqNum). The last acknowledged one (FFFEh before the first) is the
//         SendSeqNum of the ACK, NACK and ERR PDUs.
//   APMR  expects FFFFh first, then the next of each DATA taken; a DATA with the SendSeqNum just
//         taken is a retransmission (our ACK was lost): acknowledged again, not handed up twice;
//         any other SendSeqNum is out of sequence: NACKed and dropped. Every PDU carries the last
//         SendSeqNum taken (FFFEh before the first) as AckSeqNum. [A first DATA numbered 0 is taken
//         too: public references disagree on whether the first number is FFFFh or 0.]
//
// A DATA is sent with TACK set and retransmitted after the RTA timeout (RTATimeoutFactor × 100 ms)
// up to RTARetries times; then the endpoint is TimedOut (the AR ends). ACK, NACK and ERR go out
// once, TACK clear. A NACK received makes the DATA in flight go out again at once (it counts as a
// retry). The owner hands received RTA-PDUs of its priority to on_pdu() and decides whether a new
// DATA is taken (accept()): one it cannot take yet is neither acknowledged nor numbered, so the
// peer sends it again. Nothing allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/alarm.hpp"
#include "adapters/profinet/wire/blocks.hpp"
#include "adapters/profinet/wire/ethernet.hpp"
#include "core/clock.hpp"

namespace drivegate::profinet {

// One RTA timeout unit [IEC 61158-6-10, RTATimeoutFactor]: 100 ms.
inline constexpr core::Duration kRtaTimeoutUnit = std::chrono::milliseconds(100);

enum class AlarmCrError : std::uint8_t {
  None,
  BadTimeoutFactor,  // RTATimeoutFactor outside 1..100
  BadRetries,        // RTARetries outside 3..15
};
std::string_view to_string(AlarmCrError e) noexcept;
// Checks the AlarmCRBlockReq fields the transport uses [IEC 61158-6-10, AlarmCRBlockReq:
// RTATimeoutFactor 0001h-0064h, RTARetries 3-15].
AlarmCrError validate_alarm_cr(const AlarmCrBlockReq& cr) noexcept;

// describe() (wire/rpc_status.hpp) of the PNIOStatus an ERR-RTA-PDU carries.
std::string_view describe(const RtaPnioStatus& status, std::span<char> out) noexcept;

struct RtaEndpointConfig {
  MacAddress own_mac{};
  MacAddress peer_mac{};
  std::uint16_t own_ref = 0;   // AlarmSrcEndpoint of our PDUs, AlarmDstEndpoint of the peer's
  std::uint16_t peer_ref = 0;  // AlarmDstEndpoint of our PDUs
  AlarmPriority priority = AlarmPriority::High;
  std::uint16_t tag_header = 0xC000;  // the AlarmCR's TagHeaderHigh/Low: PCP bits 13-15, VID bits 0-11
  core::Duration timeout = kRtaTimeoutUnit;
  std::uint16_t retries = 3;
};

// The endpoint of one priority as the AlarmCR block request sets it up (`own` is the side that
// sends with this config).
RtaEndpointConfig rta_endpoint_config(const AlarmCrBlockReq& cr, AlarmPriority priority, const MacAddress& own_mac,
                                      const MacAddress& peer_mac, std::uint16_t own_ref,
                                      std::uint16_t peer_ref) noexcept;

// What a received frame is for the alarm CR of one AR, checked in this order.
enum class RtaFrameCheck : std::uint8_t {
  NotAlarm,       // not an alarm frame (FrameID other than FC01h/FE01h, or not PROFINET)
  WrongSource,    // from another MAC than the peer's
  Malformed,      // the RTA-PDU does not decode (decode_rta)
  WrongEndpoint,  // AlarmDstEndpoint/AlarmSrcEndpoint are not this AR's alarm references
  Ok,
};
struct RtaFrame {
  RtaFrameCheck check = RtaFrameCheck::NotAlarm;
  AlarmPriority priority = AlarmPriority::High;
  RtaView pdu{};
};
RtaFrame check_alarm_frame(std::span<const std::uint8_t> frame, const MacAddress& peer_mac, std::uint16_t own_ref,
                           std::uint16_t peer_ref) noexcept;

struct RtaCounters {
  std::uint64_t data_sent = 0;        // DATA frames, first sends
  std::uint64_t retransmissions = 0;  // DATA frames sent again (timeout or NACK)
  std::uint64_t confirmed = 0;        // our DATA acknowledged
  std::uint64_t taken = 0;            // new DATA taken from the peer
  std::uint64_t duplicates = 0;       // the DATA just taken again: acknowledged again
  std::uint64_t out_of_sequence = 0;  // another SendSeqNum: NACKed, dropped
  std::uint64_t stale_acks = 0;       // an ACK with an AckSeqNum that is not the DATA in flight
  std::uint64_t acks_sent = 0, nacks_sent = 0, errors_sent = 0;
  std::uint64_t nacks_received = 0, errors_received = 0;
  std::uint64_t tx_too_small = 0;     // poll() buffer shorter than the frame (counted as lost)
};

enum class RtaState : std::uint8_t { Closed, Open, TimedOut };

class RtaEndpoint {
 public:
  // What one received PDU means for the owner.
  struct Input {
    bool confirmed = false;  // our DATA in flight was acknowledged by it
    bool data = false;       // a new DATA in sequence: var_part holds its block; accept() or not
    bool error = false;      // an ERR-RTA-PDU: status
    std::span<const std::uint8_t> var_part{};
    RtaPnioStatus status{};
  };

  explicit RtaEndpoint(const RtaEndpointConfig& config) noexcept;

  // Starts with the initial sequence numbers (a new AR); drops what was pending.
  void open() noexcept;
  // Nothing more is sent or taken (an ERR already due still goes out).
  void close() noexcept;
  [[nodiscard]] RtaState state() const noexcept { return state_; }
  [[nodiscard]] const RtaEndpointConfig& config() const noexcept { return config_; }

  // The PDU of a frame of this priority from the peer, endpoints checked by the owner.
  Input on_pdu(const RtaView& pdu) noexcept;
  // Takes the new DATA on_pdu() reported: numbered, acknowledged at the next poll().
  void accept() noexcept;

  // True when no DATA is in flight (a new one may be sent).
  [[nodiscard]] bool can_send() const noexcept { return state_ == RtaState::Open && !in_flight_; }
  // Where the owner writes the next DATA's block; then send_data(its length).
  [[nodiscard]] std::span<std::uint8_t> data_block() noexcept;
  bool send_data(std::size_t block_length) noexcept;
  // An ERR-RTA-PDU with `status` goes out at the next poll(); the endpoint closes.
  void send_error(const RtaPnioStatus& status) noexcept;

  // At most one frame into `out`: ERR, then ACK/NACK, then the DATA when due. Moves to TimedOut
  // when the DATA was not acknowledged after 1 + retries sends.
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept;
  // TimePoint::min() while a frame is due, the DATA's retransmission time, or max().
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;
  [[nodiscard]] const RtaCounters& counters() const noexcept { return counters_; }

 private:
  enum class Reply : std::uint8_t { None, Ack, Nack };
  std::size_t write_control(RtaPduType type, std::span<std::uint8_t> out) noexcept;
  std::size_t send_in_flight(core::TimePoint now, std::span<std::uint8_t> out) noexcept;

  RtaEndpointConfig config_;
  RtaState state_ = RtaState::Closed;
  // APMS
  std::uint16_t send_seq_ = kRtaInitialSendSeq;   // of the DATA in flight or the next one
  std::uint16_t acked_seq_ = kRtaInitialAckSeq;   // the last of ours acknowledged
  bool in_flight_ = false;
  bool data_due_ = false;     // the DATA in flight goes out at the next poll (first send or NACK)
  int sends_ = 0;
  core::TimePoint resend_at_{};
  std::size_t pdu_offset_ = 0;  // where the RTA header starts in data_frame_
  std::size_t data_size_ = 0;
  std::array<std::uint8_t, kMaxFrameSize> data_frame_{};
  // APMR
  std::uint16_t expected_ = kRtaInitialSendSeq;   // SendSeqNum of the next new DATA
  std::uint16_t taken_seq_ = kRtaInitialAckSeq;   // the last taken (AckSeqNum of our PDUs)
  bool taken_any_ = false;
  std::uint16_t offered_seq_ = 0;                 // the DATA on_pdu() just reported
  Reply reply_ = Reply::None;
  bool error_due_ = false;
  RtaPnioStatus error_status_{};
  RtaCounters counters_{};
};

}  // namespace drivegate::profinet
