#include "adapters/profinet/controller/alarm_channel.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>

#include "adapters/profinet/wire/rpc_status.hpp"

namespace drivegate::profinet {

namespace {

// printf-style pieces appended to one line in a caller's buffer, cut when it is full.
class Line {
 public:
  explicit Line(std::span<char> out) noexcept : out_(out) {}
  __attribute__((format(printf, 2, 3))) void add(const char* fmt, ...) noexcept {
    if (out_.size() - n_ <= 1) return;
    va_list args;
    va_start(args, fmt);
    const int k = std::vsnprintf(out_.data() + n_, out_.size() - n_, fmt, args);
    va_end(args);
    if (k > 0) n_ = std::min(out_.size() - 1, n_ + static_cast<std::size_t>(k));
  }
  [[nodiscard]] std::string_view view() const noexcept { return {out_.data(), n_}; }

 private:
  std::span<char> out_;
  std::size_t n_ = 0;
};

// ChannelProperties [IEC 61158-6-10, coding of the field ChannelProperties].
const char* direction_name(std::uint8_t d) noexcept {
  switch (d) {
    case 0: return "manufacturer specific";
    case 1: return "input";
    case 2: return "output";
    case 3: return "input/output";
    default: return "reserved direction";
  }
}
const char* specifier_name(std::uint8_t s) noexcept {
  switch (s) {
    case 1: return "appears";
    case 2: return "disappears";
    case 3: return "disappears, others remain";
    default: return "all disappear";
  }
}
const char* maintenance_name(std::uint8_t m) noexcept {
  switch (m) {
    case 1: return "maintenance required";
    case 2: return "maintenance demanded";
    case 3: return "qualified";
    default: return "fault";
  }
}

bool is_channel_diagnosis(std::uint16_t usi) noexcept {
  return usi == user_structure::kChannelDiagnosis || usi == user_structure::kExtChannelDiagnosis ||
         usi == user_structure::kQualifiedChannelDiagnosis;
}

void add_user_structure(Line& line, const AlarmNotification& n) noexcept {
  if (!n.has_user_structure) return;
  const std::uint16_t usi = n.user_structure_id;
  if (!is_channel_diagnosis(usi)) {
    line.add("; %.*s (USI 0x%04X), %zu octets", static_cast<int>(user_structure_name(usi).size()),
             user_structure_name(usi).data(), usi, n.user_data.size());
    return;
  }
  const ChannelDiagnosisList list = decode_channel_diagnosis(usi, n.user_data);
  if (list.error != AlarmError::None) {
    line.add("; %.*s data not readable: %.*s", static_cast<int>(user_structure_name(usi).size()),
             user_structure_name(usi).data(), static_cast<int>(to_string(list.error).size()),
             to_string(list.error).data());
    return;
  }
  ChannelDiagnosis d;
  for (std::size_t i = 0; list.get(i, d); ++i) {
    const std::string_view error = channel_error_type_name(d.error_type);
    if (d.channel == kChannelWholeSubmodule) {
      line.add("; submodule");
    } else {
      line.add("; channel %u", static_cast<unsigned>(d.channel));
    }
    line.add(" (%s) %.*s (0x%04X), %s, %s", direction_name(d.direction()), static_cast<int>(error.size()),
             error.data(), d.error_type, specifier_name(d.specifier()), maintenance_name(d.maintenance()));
    if (d.accumulative()) line.add(", accumulative");
    if (usi != user_structure::kChannelDiagnosis) {
      line.add(", ext 0x%04X value 0x%08X", d.ext_error_type, static_cast<unsigned>(d.ext_add_value));
    }
    if (usi == user_structure::kQualifiedChannelDiagnosis) {
      line.add(", qualifier 0x%08X", static_cast<unsigned>(d.qualifier));
    }
  }
}

// RTA protocol error, ErrorCode2 "AR alarm-ack-send.cnf(-)" [IEC 61158-6-10, ErrorCode2 for
// ErrorDecode PNIO and ErrorCode1 253].
constexpr RtaPnioStatus kAckSendFailed{pnio_error_code::kRtaError, pnio_error_decode::kPnio,
                                       pnio_error_code1::kRtaProtocol, 9};

}  // namespace

std::string_view alarm_text(const AlarmNotification& n, std::span<char> out) noexcept {
  if (out.empty()) return {};
  Line line(out);
  const std::string_view type = alarm_type_name(n.alarm_type);
  line.add("alarm %s: %.*s (0x%04X)", to_string(n.priority), static_cast<int>(type.size()), type.data(),
           n.alarm_type);
  line.add(", API 0x%08X slot %u subslot 0x%04X, module 0x%08X submodule 0x%08X, sequence %u",
           static_cast<unsigned>(n.api), static_cast<unsigned>(n.slot), static_cast<unsigned>(n.subslot),
           static_cast<unsigned>(n.module_ident), static_cast<unsigned>(n.submodule_ident),
           static_cast<unsigned>(n.specifier.sequence));
  if (n.specifier.channel_diagnosis) line.add(", channel diagnosis");
  if (n.specifier.manufacturer_diagnosis) line.add(", manufacturer diagnosis");
  if (n.specifier.submodule_diagnosis) line.add(", submodule has diagnosis");
  if (n.specifier.ar_diagnosis) line.add(", AR has diagnosis");
  add_user_structure(line, n);
  return line.view();
}

std::string_view to_string(AlarmChannelState s) noexcept {
  switch (s) {
    case AlarmChannelState::Closed: return "closed";
    case AlarmChannelState::Open: return "open";
    case AlarmChannelState::Aborted: return "aborted";
  }
  return "unknown";
}

AlarmChannel::AlarmChannel(const AlarmChannelConfig& config, AlarmListener* listener) noexcept
    : config_(config),
      listener_(listener),
      error_(validate_alarm_cr(config.alarm_cr)),
      high_(rta_endpoint_config(config.alarm_cr, AlarmPriority::High, config.controller_mac, config.device_mac,
                                config.alarm_cr.local_alarm_reference, config.device_reference)),
      low_(rta_endpoint_config(config.alarm_cr, AlarmPriority::Low, config.controller_mac, config.device_mac,
                               config.alarm_cr.local_alarm_reference, config.device_reference)) {}

void AlarmChannel::open() noexcept {
  if (!ok()) return;
  state_ = AlarmChannelState::Open;
  reason_.clear();
  for (Side* s : {&high_, &low_}) {
    s->rta.open();
    s->head = 0;
    s->count = 0;
  }
}

void AlarmChannel::close() noexcept {
  state_ = AlarmChannelState::Closed;
  high_.rta.close();
  low_.rta.close();
}

bool AlarmChannel::on_frame(std::span<const std::uint8_t> frame, core::TimePoint) noexcept {
  const RtaFrame f =
      check_alarm_frame(frame, config_.device_mac, config_.alarm_cr.local_alarm_reference, config_.device_reference);
  if (f.check == RtaFrameCheck::NotAlarm) return false;
  if (state_ != AlarmChannelState::Open) {
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
    abort_by_device(s, in.status);
    return true;
  }
  if (in.confirmed) ++counters_.acks_confirmed;
  if (in.data) on_notification(s, in.var_part);
  return true;
}

void AlarmChannel::on_notification(Side& s, std::span<const std::uint8_t> block) noexcept {
  const AlarmPriority p = s.rta.config().priority;
  const std::uint16_t type = alarm_block_type(block);
  const std::uint16_t mine = p == AlarmPriority::High ? alarm_block::kNotificationHigh : alarm_block::kNotificationLow;
  const std::uint16_t other = p == AlarmPriority::High ? alarm_block::kNotificationLow : alarm_block::kNotificationHigh;
  if (type != mine) {
    ++(type == other ? counters_.wrong_priority : counters_.unexpected_block);
    return;
  }
  const AlarmNotificationView v = decode_alarm_notification(block);
  if (!v.ok()) {
    ++counters_.malformed;
    return;
  }
  if (s.count == kAckQueueDepth) {
    ++counters_.queue_full;  // not taken: the device sends it again
    return;
  }
  s.rta.accept();
  s.queue[(s.head + s.count++) % kAckQueueDepth] = ack_for(v.notification);
  ++counters_.alarms;
  const AlarmNotification& n = v.notification;
  if (n.has_user_structure && is_channel_diagnosis(n.user_structure_id) &&
      decode_channel_diagnosis(n.user_structure_id, n.user_data).error != AlarmError::None) {
    ++counters_.bad_channel_diagnosis;
  }
  if (listener_ != nullptr) listener_->on_alarm(AlarmEvent{n, alarm_text(n, text_)});
}

bool AlarmChannel::start_next_ack(Side& s) noexcept {
  if (s.count == 0 || !s.rta.can_send()) return false;
  s.in_flight = s.queue[s.head];
  s.head = (s.head + 1) % kAckQueueDepth;
  --s.count;
  return s.rta.send_data(encode_alarm_ack(s.rta.data_block(), s.in_flight));
}

void AlarmChannel::abort_on_timeout(Side& s) noexcept {
  const AlarmAck& a = s.in_flight;
  const std::string_view type = alarm_type_name(a.alarm_type);
  reason_.format(
      "alarm %s: the AlarmAck of the %.*s alarm (slot %u subslot 0x%04X, sequence %u) was not acknowledged after %d "
      "frames (RTA timeout %g ms, %u retries); ERR sent to the device (CF 81 FD 09)",
      to_string(s.rta.config().priority), static_cast<int>(type.size()), type.data(),
      static_cast<unsigned>(a.slot), static_cast<unsigned>(a.subslot), static_cast<unsigned>(a.specifier.sequence),
      1 + s.rta.config().retries, static_cast<double>(s.rta.config().timeout.count()) / 1e6,
      static_cast<unsigned>(s.rta.config().retries));
  state_ = AlarmChannelState::Aborted;
  s.rta.send_error(kAckSendFailed);
  (&s == &high_ ? low_ : high_).rta.close();
}

void AlarmChannel::abort_by_device(Side& s, const RtaPnioStatus& status) noexcept {
  std::array<char, 160> text{};
  const std::string_view why = describe(status, text);
  reason_.format("alarm %s: the device aborted the alarm CR (ERR-RTA-PDU): %.*s", to_string(s.rta.config().priority),
                 static_cast<int>(why.size()), why.data());
  state_ = AlarmChannelState::Aborted;
  high_.rta.close();
  low_.rta.close();
}

std::size_t AlarmChannel::poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept {
  for (Side* s : {&high_, &low_}) {
    // An ERR due goes out even after the abort.
    std::size_t n = s->rta.poll(now, out);
    if (n != 0) return n;
    if (state_ != AlarmChannelState::Open) continue;
    if (s->rta.state() == RtaState::TimedOut) {
      abort_on_timeout(*s);
      return poll(now, out);
    }
    if (start_next_ack(*s) && (n = s->rta.poll(now, out)) != 0) return n;
  }
  return 0;
}

core::TimePoint AlarmChannel::next_deadline() const noexcept {
  core::TimePoint t = core::TimePoint::max();
  for (const Side* s : {&high_, &low_}) {
    t = std::min(t, s->rta.next_deadline());
    if (state_ == AlarmChannelState::Open && s->count > 0 && s->rta.can_send()) t = core::TimePoint::min();
  }
  return t;
}

}  // namespace drivegate::profinet
