#include "adapters/profinet/controller/rta_endpoint.hpp"

#include <algorithm>

#include "adapters/profinet/wire/rpc_status.hpp"

namespace drivegate::profinet {

namespace {

constexpr std::uint16_t kMaxTimeoutFactor = 100;  // 0064h
constexpr std::uint16_t kMinRetries = 3;
constexpr std::uint16_t kMaxRetries = 15;

EthernetHeader header_for(const RtaEndpointConfig& c) noexcept {
  EthernetHeader h;
  h.dst = c.peer_mac;
  h.src = c.own_mac;
  h.vlan = true;
  h.priority = static_cast<std::uint8_t>(c.tag_header >> 13);
  h.vlan_id = c.tag_header & 0x0FFF;
  h.frame_id = c.priority == AlarmPriority::High ? frame_id::kAlarmHigh : frame_id::kAlarmLow;
  return h;
}

}  // namespace

std::string_view to_string(AlarmCrError e) noexcept {
  switch (e) {
    case AlarmCrError::None: return "ok";
    case AlarmCrError::BadTimeoutFactor: return "RTATimeoutFactor outside 1..100";
    case AlarmCrError::BadRetries: return "RTARetries outside 3..15";
  }
  return "unknown";
}

AlarmCrError validate_alarm_cr(const AlarmCrBlockReq& cr) noexcept {
  if (cr.rta_timeout_factor < 1 || cr.rta_timeout_factor > kMaxTimeoutFactor) return AlarmCrError::BadTimeoutFactor;
  if (cr.rta_retries < kMinRetries || cr.rta_retries > kMaxRetries) return AlarmCrError::BadRetries;
  return AlarmCrError::None;
}

std::string_view describe(const RtaPnioStatus& status, std::span<char> out) noexcept {
  return describe(PnioStatus{status.code, status.decode, status.code1, status.code2}, out);
}

RtaFrame check_alarm_frame(std::span<const std::uint8_t> frame, const MacAddress& peer_mac, std::uint16_t own_ref,
                           std::uint16_t peer_ref) noexcept {
  RtaFrame f;
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok() || !is_alarm(e.frame_class)) return f;
  f.priority = e.frame_class == FrameClass::AlarmHigh ? AlarmPriority::High : AlarmPriority::Low;
  if (e.header.src != peer_mac) {
    f.check = RtaFrameCheck::WrongSource;
    return f;
  }
  f.pdu = decode_rta(e.pdu);
  if (!f.pdu.ok()) {
    f.check = RtaFrameCheck::Malformed;
  } else if (f.pdu.header.dst_endpoint != own_ref || f.pdu.header.src_endpoint != peer_ref) {
    f.check = RtaFrameCheck::WrongEndpoint;
  } else {
    f.check = RtaFrameCheck::Ok;
  }
  return f;
}

RtaEndpointConfig rta_endpoint_config(const AlarmCrBlockReq& cr, AlarmPriority priority, const MacAddress& own_mac,
                                      const MacAddress& peer_mac, std::uint16_t own_ref,
                                      std::uint16_t peer_ref) noexcept {
  RtaEndpointConfig c;
  c.own_mac = own_mac;
  c.peer_mac = peer_mac;
  c.own_ref = own_ref;
  c.peer_ref = peer_ref;
  c.priority = priority;
  c.tag_header = priority == AlarmPriority::High ? cr.tag_header_high : cr.tag_header_low;
  c.timeout = kRtaTimeoutUnit * cr.rta_timeout_factor;
  c.retries = cr.rta_retries;
  return c;
}

RtaEndpoint::RtaEndpoint(const RtaEndpointConfig& config) noexcept
    : config_(config) {
  pdu_offset_ = encode_ethernet_header(header_for(config_), data_frame_);
}

void RtaEndpoint::open() noexcept {
  state_ = RtaState::Open;
  send_seq_ = kRtaInitialSendSeq;
  acked_seq_ = kRtaInitialAckSeq;
  in_flight_ = false;
  data_due_ = false;
  sends_ = 0;
  expected_ = kRtaInitialSendSeq;
  taken_seq_ = kRtaInitialAckSeq;
  taken_any_ = false;
  reply_ = Reply::None;
  error_due_ = false;
}

void RtaEndpoint::close() noexcept {
  state_ = RtaState::Closed;
  in_flight_ = false;
  data_due_ = false;
  reply_ = Reply::None;
}

RtaEndpoint::Input RtaEndpoint::on_pdu(const RtaView& pdu) noexcept {
  Input in;
  if (state_ != RtaState::Open) return in;
  const RtaHeader& h = pdu.header;
  switch (h.type) {
    case RtaPduType::Err:
      ++counters_.errors_received;
      in.error = true;
      in.status = rta_error_status(pdu);
      close();
      return in;
    case RtaPduType::Nack:
      ++counters_.nacks_received;
      // The peer did not take our DATA (window or sequence): it goes out again now, as a retry.
      if (in_flight_ && sends_ <= config_.retries) data_due_ = true;
      return in;
    case RtaPduType::Ack:
    case RtaPduType::Data: break;
  }
  if (in_flight_ && h.ack_seq == send_seq_) {
    in_flight_ = false;
    data_due_ = false;
    acked_seq_ = send_seq_;
    send_seq_ = next_rta_seq(send_seq_);
    ++counters_.confirmed;
    in.confirmed = true;
  } else if (h.type == RtaPduType::Ack) {
    ++counters_.stale_acks;  // an ACK of nothing in flight, or of an older DATA
  }
  if (h.type != RtaPduType::Data) return in;
  // A first DATA numbered 0 instead of FFFFh is taken too (see the header).
  const bool first_as_zero = !taken_any_ && h.send_seq == 0;
  if (h.send_seq == expected_ || first_as_zero) {
    offered_seq_ = h.send_seq;
    in.data = true;
    in.var_part = pdu.var_part;
    return in;
  }
  if (taken_any_ && h.send_seq == taken_seq_) {
    ++counters_.duplicates;
    reply_ = Reply::Ack;
    return in;
  }
  ++counters_.out_of_sequence;
  reply_ = Reply::Nack;
  return in;
}

void RtaEndpoint::accept() noexcept {
  ++counters_.taken;
  taken_any_ = true;
  taken_seq_ = offered_seq_;
  expected_ = next_rta_seq(offered_seq_);
  reply_ = Reply::Ack;
}

std::span<std::uint8_t> RtaEndpoint::data_block() noexcept {
  return std::span(data_frame_).subspan(pdu_offset_ + kRtaHeaderSize);
}

bool RtaEndpoint::send_data(std::size_t block_length) noexcept {
  if (!can_send() || block_length == 0 || block_length > data_block().size()) return false;
  RtaHeader h;
  h.dst_endpoint = config_.peer_ref;
  h.src_endpoint = config_.own_ref;
  h.type = RtaPduType::Data;
  h.tack = true;
  h.send_seq = send_seq_;
  h.ack_seq = taken_seq_;
  const auto pdu = std::span(data_frame_).subspan(pdu_offset_);
  const std::size_t n = encode_rta(pdu, h, pdu.subspan(kRtaHeaderSize, block_length));
  if (n == 0) return false;
  data_size_ = pad_frame(data_frame_, pdu_offset_ + n);
  in_flight_ = true;
  data_due_ = true;
  sends_ = 0;
  return true;
}

void RtaEndpoint::send_error(const RtaPnioStatus& status) noexcept {
  if (state_ == RtaState::Closed) return;
  error_due_ = true;
  error_status_ = status;
  close();
}

std::size_t RtaEndpoint::write_control(RtaPduType type, std::span<std::uint8_t> out) noexcept {
  const std::size_t at = encode_ethernet_header(header_for(config_), out);
  if (at == 0) return 0;
  RtaHeader h;
  h.dst_endpoint = config_.peer_ref;
  h.src_endpoint = config_.own_ref;
  h.type = type;
  h.send_seq = acked_seq_;
  h.ack_seq = taken_seq_;
  const std::size_t n = type == RtaPduType::Err ? encode_rta_error(out.subspan(at), h, error_status_)
                                                : encode_rta(out.subspan(at), h, {});
  return n == 0 ? 0 : pad_frame(out, at + n);
}

std::size_t RtaEndpoint::send_in_flight(core::TimePoint now, std::span<std::uint8_t> out) noexcept {
  ++(sends_ == 0 ? counters_.data_sent : counters_.retransmissions);
  ++sends_;
  data_due_ = false;
  resend_at_ = now + config_.timeout;
  if (out.size() < data_size_) {
    ++counters_.tx_too_small;  // as if lost on the wire: the timer sends it again
    return 0;
  }
  std::copy_n(data_frame_.begin(), data_size_, out.begin());
  return data_size_;
}

std::size_t RtaEndpoint::poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept {
  if (error_due_) {
    error_due_ = false;
    const std::size_t n = write_control(RtaPduType::Err, out);
    ++(n == 0 ? counters_.tx_too_small : counters_.errors_sent);
    return n;
  }
  if (state_ != RtaState::Open) return 0;
  if (reply_ != Reply::None) {
    const bool ack = reply_ == Reply::Ack;
    reply_ = Reply::None;
    const std::size_t n = write_control(ack ? RtaPduType::Ack : RtaPduType::Nack, out);
    ++(n == 0 ? counters_.tx_too_small : (ack ? counters_.acks_sent : counters_.nacks_sent));
    return n;
  }
  if (!in_flight_) return 0;
  if (data_due_) return send_in_flight(now, out);
  if (now < resend_at_) return 0;
  if (sends_ > config_.retries) {
    state_ = RtaState::TimedOut;
    in_flight_ = false;
    return 0;
  }
  return send_in_flight(now, out);
}

core::TimePoint RtaEndpoint::next_deadline() const noexcept {
  if (error_due_ || (state_ == RtaState::Open && (reply_ != Reply::None || (in_flight_ && data_due_)))) {
    return core::TimePoint::min();
  }
  return state_ == RtaState::Open && in_flight_ ? resend_at_ : core::TimePoint::max();
}

}  // namespace drivegate::profinet
