#include "adapters/profinet/controller/dcp_client.hpp"

#include <algorithm>

namespace drivegate::profinet {

namespace {

constexpr std::size_t kIndexBits = 8;

std::uint8_t copy_text(std::string_view text, std::span<char> into, bool* truncated = nullptr) noexcept {
  const std::size_t n = std::min(text.size(), into.size());
  std::copy_n(text.begin(), n, into.begin());
  if (truncated != nullptr) *truncated = n < text.size();
  return static_cast<std::uint8_t>(n);
}

}  // namespace

core::Duration identify_window(std::uint16_t response_delay_factor) noexcept {
  using std::chrono::milliseconds;
  if (response_delay_factor <= 1) return milliseconds(400);
  const std::int64_t ms = 1000 + 10 * std::int64_t{response_delay_factor};
  return milliseconds((ms + 999) / 1000 * 1000);
}

std::string_view to_string(DcpRequestStatus s) noexcept {
  switch (s) {
    case DcpRequestStatus::Unknown: return "unknown";
    case DcpRequestStatus::Queued: return "queued";
    case DcpRequestStatus::InFlight: return "in flight";
    case DcpRequestStatus::Done: return "done";
    case DcpRequestStatus::Failed: return "failed";
  }
  return "?";
}

std::string_view to_string(DcpFailure f) noexcept {
  switch (f) {
    case DcpFailure::None: return "no failure";
    case DcpFailure::Timeout: return "no response (timeout after every retry)";
    case DcpFailure::BlockError: return "the device refused the value (BlockError)";
    case DcpFailure::NotSupported: return "the device answered \"request not supported\"";
    case DcpFailure::BadResponse: return "the Set response has no result for the block sent";
    case DcpFailure::BufferTooSmall: return "the request's frame does not fit the buffer given to poll() (not sent)";
  }
  return "?";
}

DcpClient::DcpClient(const MacAddress& own_mac, DcpClientTiming timing, std::uint32_t first_xid) noexcept
    : own_mac_(own_mac), timing_(timing), next_xid_(first_xid) {}

DcpRequestId DcpClient::submit(Kind kind, const MacAddress& target, std::uint16_t option) noexcept {
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& s = slots_[i];
    if (s.state != State::Free) continue;
    ++s.generation;
    s.state = State::Queued;
    s.kind = kind;
    s.order = next_order_++;
    s.result = DcpResult{};
    s.result.status = DcpRequestStatus::Queued;
    s.result.option = option;
    s.result.target = target;
    s.result.xid = next_xid_++;
    s.into = {};
    s.abandoned = false;
    ++counters_.requests;
    return (DcpRequestId{s.generation} << kIndexBits) | static_cast<DcpRequestId>(i + 1);
  }
  ++counters_.queue_full;
  return kNoDcpRequest;
}

DcpClient::Slot* DcpClient::find(DcpRequestId id) noexcept {
  return const_cast<Slot*>(static_cast<const DcpClient*>(this)->find(id));
}

const DcpClient::Slot* DcpClient::find(DcpRequestId id) const noexcept {
  const std::size_t index = id & ((1U << kIndexBits) - 1);
  if (index == 0 || index > slots_.size()) return nullptr;
  const Slot& s = slots_[index - 1];
  if (s.state == State::Free || s.abandoned || s.generation != (id >> kIndexBits)) return nullptr;
  return &s;
}

DcpRequestId DcpClient::identify_all(std::span<DcpStation> into, std::uint16_t response_delay_factor) noexcept {
  if (response_delay_factor == 0 || response_delay_factor > kDcpMaxResponseDelayFactor) {
    ++counters_.refused;
    return kNoDcpRequest;
  }
  const DcpRequestId id = submit(Kind::IdentifyAll, kDcpIdentifyMulticast, 0);
  if (Slot* s = find(id)) {
    s->factor = response_delay_factor;
    s->into = into;
  }
  return id;
}

DcpRequestId DcpClient::identify_name(std::string_view name, std::span<DcpStation> into,
                                      std::uint16_t response_delay_factor) noexcept {
  if (response_delay_factor == 0 || response_delay_factor > kDcpMaxResponseDelayFactor ||
      validate_name_of_station(name) != NameError::None) {
    ++counters_.refused;
    return kNoDcpRequest;
  }
  const DcpRequestId id = submit(Kind::IdentifyName, kDcpIdentifyMulticast, 0);
  if (Slot* s = find(id)) {
    s->factor = response_delay_factor;
    s->into = into;
    s->name_length = copy_text(name, s->name);
  }
  return id;
}

DcpRequestId DcpClient::set_name(const MacAddress& device, std::string_view name, DcpQualifier qualifier) noexcept {
  if (validate_name_of_station(name) != NameError::None) {
    ++counters_.refused;
    return kNoDcpRequest;
  }
  const DcpRequestId id = submit(Kind::SetName, device, dcp_option::kNameOfStation);
  if (Slot* s = find(id)) {
    s->name_length = copy_text(name, s->name);
    s->qualifier = qualifier;
  }
  return id;
}

DcpRequestId DcpClient::set_ip(const MacAddress& device, const IpSuite& ip, DcpQualifier qualifier) noexcept {
  if (!ip_suite_problem(ip).empty()) {
    ++counters_.refused;
    return kNoDcpRequest;
  }
  const DcpRequestId id = submit(Kind::SetIp, device, dcp_option::kIpParameter);
  if (Slot* s = find(id)) {
    s->ip = ip;
    s->qualifier = qualifier;
  }
  return id;
}

DcpRequestId DcpClient::signal(const MacAddress& device) noexcept {
  return submit(Kind::Signal, device, dcp_option::kSignal);
}

DcpResult DcpClient::result(DcpRequestId id) const noexcept {
  const Slot* s = find(id);
  return s != nullptr ? s->result : DcpResult{};
}

std::span<const DcpStation> DcpClient::stations(DcpRequestId id) const noexcept {
  const Slot* s = find(id);
  if (s == nullptr) return {};
  return std::span<const DcpStation>(s->into).first(s->result.stations);
}

DcpResult DcpClient::take(DcpRequestId id) noexcept {
  Slot* s = find(id);
  if (s == nullptr) return DcpResult{};
  const DcpResult r = s->result;
  if (current_ >= 0 && &slots_[static_cast<std::size_t>(current_)] == s) {
    s->abandoned = true;  // stays on the wire to its end; its responses go nowhere
  } else {
    s->state = State::Free;
  }
  s->into = {};
  return r;
}

DcpClient::Slot* DcpClient::in_flight() noexcept {
  return current_ >= 0 ? &slots_[static_cast<std::size_t>(current_)] : nullptr;
}

void DcpClient::start_next() noexcept {
  int best = -1;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (slots_[i].state != State::Queued) continue;
    if (best < 0 || slots_[i].order < slots_[static_cast<std::size_t>(best)].order) best = static_cast<int>(i);
  }
  current_ = best;
  if (best >= 0) {
    Slot& s = slots_[static_cast<std::size_t>(best)];
    s.state = State::Sending;
    s.result.status = DcpRequestStatus::InFlight;
  }
}

void DcpClient::finish(Slot& s, DcpFailure failure) noexcept {
  s.result.failure = failure;
  const bool ok = failure == DcpFailure::None;
  s.result.status = ok ? DcpRequestStatus::Done : DcpRequestStatus::Failed;
  ++(ok ? counters_.completed : counters_.failed);
  s.state = s.abandoned ? State::Free : (ok ? State::Done : State::Failed);
  current_ = -1;
}

std::size_t DcpClient::encode(Slot& s, std::span<std::uint8_t> out) noexcept {
  EthernetHeader h;
  h.dst = s.result.target;
  h.src = own_mac_;
  h.frame_id = is_identify(s.kind) ? frame_id::kDcpIdentifyRequest : frame_id::kDcpGetSet;
  const std::size_t at = encode_ethernet_header(h, out);
  if (at == 0) return 0;
  const auto pdu = out.subspan(at);
  const std::uint32_t xid = s.result.xid;
  std::size_t n = 0;
  switch (s.kind) {
    case Kind::IdentifyAll: n = encode_identify_all_request(pdu, xid, s.factor); break;
    case Kind::IdentifyName: n = encode_identify_name_request(pdu, xid, s.factor, name_of(s)); break;
    case Kind::SetName: n = encode_set_name_request(pdu, xid, name_of(s), s.qualifier); break;
    case Kind::SetIp: n = encode_set_ip_request(pdu, xid, s.ip, s.qualifier); break;
    case Kind::Signal: n = encode_set_signal_request(pdu, xid); break;
  }
  return n == 0 ? 0 : pad_frame(out, at + n);
}

std::size_t DcpClient::poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept {
  for (;;) {
    if (current_ < 0) start_next();
    Slot* s = in_flight();
    if (s == nullptr) return 0;
    if (s->state == State::Waiting) {
      if (now < s->deadline) return 0;
      if (is_identify(s->kind)) {
        finish(*s, DcpFailure::None);  // the window closed: whoever answered is in the list
        continue;
      }
      if (s->result.frames_sent > timing_.set_retries) {
        ++counters_.timeouts;
        finish(*s, DcpFailure::Timeout);
        continue;
      }
      ++counters_.retries;
      s->state = State::Sending;
    }
    const std::size_t n = encode(*s, out);
    if (n == 0) {
      // Kept due, the same frame would not fit the next poll() either: the request ends here,
      // as RtProvider drops a slot it cannot write.
      ++counters_.tx_too_small;
      finish(*s, DcpFailure::BufferTooSmall);
      continue;
    }
    ++s->result.frames_sent;
    ++counters_.frames_sent;
    s->deadline = now + (is_identify(s->kind) ? identify_window(s->factor) : timing_.set_timeout);
    s->state = State::Waiting;
    return n;
  }
}

core::TimePoint DcpClient::next_deadline() const noexcept {
  if (current_ < 0) return idle() ? core::TimePoint::max() : core::TimePoint::min();
  const Slot& s = slots_[static_cast<std::size_t>(current_)];
  return s.state == State::Waiting ? s.deadline : core::TimePoint::min();
}

bool DcpClient::idle() const noexcept {
  return current_ < 0 &&
         std::none_of(slots_.begin(), slots_.end(), [](const Slot& s) { return s.state == State::Queued; });
}

bool DcpClient::on_frame(std::span<const std::uint8_t> frame, core::TimePoint) noexcept {
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok() || !is_dcp(e.frame_class)) return false;
  const DcpPdu pdu = decode_dcp(e.pdu);
  if (!pdu.ok()) {
    ++counters_.malformed;
    return true;
  }
  if (pdu.header.type == DcpServiceType::Request) {
    ++counters_.requests_seen;  // an Identify of another controller, a Hello, a Get/Set not for us
    return true;
  }
  if (e.header.dst != own_mac_) {
    ++counters_.not_for_us;  // a response to another controller (a port that sees all traffic)
    return true;
  }
  Slot* s = in_flight();
  if (s == nullptr || s->result.frames_sent == 0) {
    ++counters_.unsolicited;
    return true;
  }
  if (pdu.header.xid != s->result.xid) {
    ++counters_.foreign_xid;
    return true;
  }
  if (is_identify(s->kind)) {
    if (e.frame_class != FrameClass::DcpIdentifyResponse || pdu.header.service != DcpService::Identify ||
        pdu.header.type != DcpServiceType::ResponseSuccess) {
      ++counters_.wrong_service;
      return true;
    }
    on_identify_response(*s, e, pdu);
  } else {
    if (e.frame_class != FrameClass::DcpGetSet || pdu.header.service != DcpService::Set) {
      ++counters_.wrong_service;
      return true;
    }
    on_set_response(*s, e, pdu);
  }
  return true;
}

void DcpClient::on_identify_response(Slot& s, const EthernetView& e, const DcpPdu& pdu) noexcept {
  const DcpDeviceInfoView v = decode_device_info(pdu);
  if (v.error != DcpError::None) {
    ++counters_.malformed;
    return;
  }
  const DcpDeviceInfo& d = v.info;
  if (s.kind == Kind::IdentifyName && (!d.has_name_of_station || d.name_of_station != name_of(s))) {
    ++counters_.wrong_name;
    return;
  }
  const auto found = std::span<const DcpStation>(s.into).first(s.result.stations);
  if (std::any_of(found.begin(), found.end(), [&](const DcpStation& st) { return st.mac == e.header.src; })) {
    ++counters_.duplicate_answers;
    return;
  }
  ++counters_.responses;
  if (s.result.stations >= s.into.size()) {  // also after take(): `into` is then empty
    ++s.result.stations_lost;
    return;
  }
  DcpStation& st = s.into[s.result.stations++];
  st = DcpStation{};
  st.mac = e.header.src;
  st.has_name = d.has_name_of_station;
  st.name_length = copy_text(d.name_of_station, st.name_chars);
  st.has_type_of_station = d.has_type_of_station;
  st.type_length = copy_text(d.type_of_station, st.type_chars, &st.type_truncated);
  st.has_device_id = d.has_device_id;
  st.vendor_id = d.vendor_id;
  st.device_id = d.device_id;
  st.has_device_role = d.has_device_role;
  st.device_role = d.device_role;
  st.has_ip = d.has_ip;
  st.ip_block_info = d.ip_block_info;
  st.ip = d.ip;
}

void DcpClient::on_set_response(Slot& s, const EthernetView& e, const DcpPdu& pdu) noexcept {
  if (e.header.src != s.result.target) {
    ++counters_.wrong_source;
    return;
  }
  ++counters_.responses;
  if (pdu.header.type == DcpServiceType::ResponseNotSupported) {
    finish(s, DcpFailure::NotSupported);
    return;
  }
  std::array<DcpSetResult, 4> results{};
  const DcpSetResponse r = decode_set_response(pdu, results);
  if (r.error != DcpError::None) {
    --counters_.responses;
    ++counters_.malformed;
    return;
  }
  for (std::size_t i = 0; i < r.count; ++i) {
    if (results[i].id != s.result.option) continue;
    s.result.block_error = results[i].error;
    finish(s, results[i].error == DcpBlockError::NoError ? DcpFailure::None : DcpFailure::BlockError);
    return;
  }
  finish(s, DcpFailure::BadResponse);
}

}  // namespace drivegate::profinet
