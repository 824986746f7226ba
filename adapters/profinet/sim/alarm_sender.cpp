#include "adapters/profinet/sim/alarm_sender.hpp"

#include <algorithm>

#include "adapters/profinet/wire/rpc_status.hpp"

namespace drivegate::profinet {

namespace {

// RTA protocol error, ErrorCode2 "AR alarm-send.cnf(-)" [IEC 61158-6-10, ErrorCode2 for
// ErrorDecode PNIO and ErrorCode1 253].
constexpr RtaPnioStatus kSendFailed{pnio_error_code::kRtaError, pnio_error_decode::kPnio,
                                    pnio_error_code1::kRtaProtocol, 8};

bool echoes(const AlarmAck& a, const AlarmNotification& n) noexcept {
  return a.alarm_type == n.alarm_type && a.api == n.api && a.slot == n.slot && a.subslot == n.subslot &&
         a.specifier.sequence == n.specifier.sequence;
}

}  // namespace

std::string_view to_string(AlarmSenderState s) noexcept {
  switch (s) {
    case AlarmSenderState::Closed: return "closed";
    case AlarmSenderState::Open: return "open";
    case AlarmSenderState::Aborted: return "aborted";
  }
  return "unknown";
}

AlarmSender::AlarmSender(const AlarmSenderConfig& config) noexcept
    : config_(config),
      error_(validate_alarm_cr(config.alarm_cr)),
      high_(rta_endpoint_config(config.alarm_cr, AlarmPriority::High, config.device_mac, config.controller_mac,
                                config.device_reference, config.alarm_cr.local_alarm_reference)),
      low_(rta_endpoint_config(config.alarm_cr, AlarmPriority::Low, config.device_mac, config.controller_mac,
                               config.device_reference, config.alarm_cr.local_alarm_reference)) {}

void AlarmSender::open() noexcept {
  if (error_ != AlarmCrError::None) return;
  state_ = AlarmSenderState::Open;
  reason_.clear();
  for (Side* s : {&high_, &low_}) {
    s->rta.open();
    s->head = 0;
    s->count = 0;
    s->sent = false;
    s->sequence = 0;
  }
}

void AlarmSender::close() noexcept {
  state_ = AlarmSenderState::Closed;
  high_.rta.close();
  low_.rta.close();
}

bool AlarmSender::send(const AlarmNotification& n) noexcept {
  Side& s = side(n.priority);
  if (state_ != AlarmSenderState::Open || s.count == kQueueDepth || n.user_data.size() > kMaxAlarmData ||
      (!n.has_user_structure && !n.user_data.empty())) {
    ++counters_.refused;
    return false;
  }
  Alarm& a = s.queue[(s.head + s.count++) % kQueueDepth];
  a.n = n;
  a.n.user_data = {};
  a.n.specifier.sequence = s.sequence;
  s.sequence = next_alarm_sequence(s.sequence);
  a.length = n.user_data.size();
  std::copy(n.user_data.begin(), n.user_data.end(), a.data.begin());
  ++counters_.queued;
  return true;
}

void AlarmSender::abort(const RtaPnioStatus& status) noexcept {
  if (state_ != AlarmSenderState::Open) return;
  high_.rta.close();
  low_.rta.send_error(status);
  std::array<char, 160> text{};
  const std::string_view why = describe(status, text);
  reason_.format("aborted by the device: %.*s", static_cast<int>(why.size()), why.data());
  state_ = AlarmSenderState::Aborted;
}

bool AlarmSender::on_frame(std::span<const std::uint8_t> frame, core::TimePoint) noexcept {
  const RtaFrame f =
      check_alarm_frame(frame, config_.controller_mac, config_.device_reference, config_.alarm_cr.local_alarm_reference);
  if (f.check == RtaFrameCheck::NotAlarm) return false;
  if (state_ != AlarmSenderState::Open) {
    ++counters_.inactive;
    return true;
  }
  switch (f.check) {
    case RtaFrameCheck::NotAlarm:
    case RtaFrameCheck::Ok: break;
    case RtaFrameCheck::WrongSource: ++counters_.wrong_source; return true;
    case RtaFrameCheck::Malformed: ++counters_.malformed; return true;
    case RtaFrameCheck::WrongEndpoint: ++counters_.wrong_endpoint; return true;
  }
  Side& s = side(f.priority);
  const RtaEndpoint::Input in = s.rta.on_pdu(f.pdu);
  if (in.error) {
    (&s == &high_ ? low_ : high_).rta.close();
    std::array<char, 160> text{};
    const std::string_view why = describe(in.status, text);
    reason_.format("the controller aborted the alarm CR (ERR-RTA-PDU): %.*s", static_cast<int>(why.size()), why.data());
    state_ = AlarmSenderState::Aborted;
    return true;
  }
  if (in.data) on_data(s, in.var_part);
  return true;
}

void AlarmSender::on_data(Side& s, std::span<const std::uint8_t> block) noexcept {
  const std::uint16_t mine = s.rta.config().priority == AlarmPriority::High ? alarm_block::kAckHigh : alarm_block::kAckLow;
  if (alarm_block_type(block) != mine) {
    ++counters_.unexpected_block;
    return;
  }
  const AlarmAckView v = decode_alarm_ack(block);
  if (!v.ok()) {
    ++counters_.malformed;
    return;
  }
  s.rta.accept();
  if (!s.sent || !echoes(v.ack, s.queue[s.head].n)) {
    ++counters_.unmatched_acks;
    return;
  }
  s.last_status = v.ack.status;
  ++(v.ack.status.ok() ? counters_.acknowledged : counters_.refused_by_controller);
  s.sent = false;
  s.head = (s.head + 1) % kQueueDepth;
  --s.count;
}

bool AlarmSender::start_next(Side& s) noexcept {
  if (s.sent || s.count == 0 || !s.rta.can_send()) return false;
  Alarm& a = s.queue[s.head];
  AlarmNotification n = a.n;
  n.user_data = std::span<const std::uint8_t>(a.data).first(a.length);
  s.sent = s.rta.send_data(encode_alarm_notification(s.rta.data_block(), n));
  return s.sent;
}

std::size_t AlarmSender::poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept {
  for (Side* s : {&high_, &low_}) {
    std::size_t n = s->rta.poll(now, out);
    if (n != 0) return n;
    if (state_ != AlarmSenderState::Open) continue;
    if (s->rta.state() == RtaState::TimedOut) {
      s->rta.send_error(kSendFailed);
      (s == &high_ ? low_ : high_).rta.close();
      reason_.format("alarm %s: no ACK from the controller after %u frames; ERR sent (CF 81 FD 08)",
                     to_string(s->rta.config().priority), 1U + s->rta.config().retries);
      state_ = AlarmSenderState::Aborted;
      return poll(now, out);
    }
    if (start_next(*s) && (n = s->rta.poll(now, out)) != 0) return n;
  }
  return 0;
}

core::TimePoint AlarmSender::next_deadline() const noexcept {
  core::TimePoint t = core::TimePoint::max();
  for (const Side* s : {&high_, &low_}) {
    t = std::min(t, s->rta.next_deadline());
    if (state_ == AlarmSenderState::Open && !s->sent && s->count > 0 && s->rta.can_send()) t = core::TimePoint::min();
  }
  return t;
}

}  // namespace drivegate::profinet
