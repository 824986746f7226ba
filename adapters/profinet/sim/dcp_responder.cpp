#include "adapters/profinet/sim/dcp_responder.hpp"

#include <algorithm>
#include <stdexcept>

#include "adapters/profinet/wire/byte_order.hpp"

namespace drivegate::profinet {

namespace {

// The options this device has (the DeviceOptions block of its Identify response, and what a Get
// may ask for) [IEC 61158-6-10 §4.3, DeviceOptions].
constexpr std::array<std::uint16_t, 9> kOptions{
    dcp_option::kMacAddress,     dcp_option::kIpParameter, dcp_option::kTypeOfStation,
    dcp_option::kNameOfStation,  dcp_option::kDeviceId,    dcp_option::kDeviceRole,
    dcp_option::kDeviceOptions,  dcp_option::kDeviceInstance, dcp_option::kSignal,
};
constexpr auto kOptionBytes = [] {
  std::array<std::uint8_t, 2 * kOptions.size()> b{};
  for (std::size_t i = 0; i < kOptions.size(); ++i) {
    b[2 * i] = dcp_option::option_of(kOptions[i]);
    b[2 * i + 1] = dcp_option::suboption_of(kOptions[i]);
  }
  return b;
}();

constexpr std::uint8_t kOptionIp = 1, kOptionDevice = 2, kOptionControl = 5;

bool option_known(std::uint8_t option) noexcept {
  return option == kOptionIp || option == kOptionDevice || option == kOptionControl;
}

std::string_view text_of(std::span<const std::uint8_t> b) noexcept {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

}  // namespace

DcpResponder::DcpResponder(const DcpResponderConfig& config)
    : mac_(config.mac),
      type_of_station_(config.type_of_station),
      vendor_id_(config.vendor_id),
      device_id_(config.device_id),
      device_role_(config.device_role),
      instance_high_(config.instance_high),
      instance_low_(config.instance_low) {
  if (!config.name_of_station.empty() && validate_name_of_station(config.name_of_station) != NameError::None) {
    throw std::invalid_argument("DCP responder: NameOfStation \"" + config.name_of_station +
                                "\": " + std::string(to_string(validate_name_of_station(config.name_of_station))));
  }
  if (const std::string_view p = ip_suite_problem(config.ip); !p.empty()) {
    throw std::invalid_argument("DCP responder: IP suite: " + std::string(p));
  }
  if (type_of_station_.size() > kMaxNameOfStationLength) {
    throw std::invalid_argument("DCP responder: TypeOfStation longer than 240 octets");
  }
  std::copy(config.name_of_station.begin(), config.name_of_station.end(), stored_name_.begin());
  stored_name_length_ = config.name_of_station.size();
  stored_ip_ = config.ip;
  power_cycle();
}

void DcpResponder::power_cycle() noexcept {
  name_ = stored_name_;
  name_length_ = stored_name_length_;
  ip_ = stored_ip_;
  for (TxSlot& t : tx_) t.used = false;
  have_last_ = false;
  in_operation_ = false;
}

core::Duration DcpResponder::response_delay(std::uint16_t factor) const noexcept {
  factor = std::clamp<std::uint16_t>(factor, 1, kDcpMaxResponseDelayFactor);
  const unsigned r = (unsigned{mac_[4]} << 8) | mac_[5];
  return std::chrono::milliseconds(10 * (r % factor));
}

DcpDeviceInfo DcpResponder::device_info() const noexcept {
  DcpDeviceInfo d;
  d.has_type_of_station = true;
  d.type_of_station = type_of_station_;
  d.has_name_of_station = true;  // empty when the device has no name
  d.name_of_station = name_of_station();
  d.has_device_id = true;
  d.vendor_id = vendor_id_;
  d.device_id = device_id_;
  d.has_device_role = true;
  d.device_role = device_role_;
  d.has_device_options = true;
  d.device_options = kOptionBytes;
  d.has_device_instance = true;
  d.instance_high = instance_high_;
  d.instance_low = instance_low_;
  d.has_ip = true;
  d.ip = ip_;
  d.ip_block_info = ip_ == IpSuite{} ? ip_block_info::kNotSet : ip_block_info::kSet;
  return d;
}

DcpResponder::TxSlot* DcpResponder::reserve(core::TimePoint due) noexcept {
  for (TxSlot& t : tx_) {
    if (t.used) continue;
    t.due = due;
    return &t;
  }
  ++counters_.tx_dropped;
  return nullptr;
}

bool DcpResponder::commit(TxSlot& slot, const MacAddress& to, std::uint16_t frame_id, std::size_t pdu_length) noexcept {
  if (pdu_length == 0) return false;
  EthernetHeader h;
  h.dst = to;
  h.src = mac_;
  h.frame_id = frame_id;
  const std::size_t at = encode_ethernet_header(h, slot.frame);
  slot.length = pad_frame(slot.frame, at + pdu_length);
  slot.used = slot.length != 0;
  return slot.used;
}

// The PDU part of a slot's frame: after an untagged header with its FrameID.
namespace {
std::span<std::uint8_t> pdu_area(std::span<std::uint8_t> frame) noexcept {
  return frame.subspan(kEthernetHeaderSize + kFrameIdSize);
}
}  // namespace

bool DcpResponder::on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept {
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok() || !is_dcp(e.frame_class)) return false;
  const DcpPdu pdu = decode_dcp(e.pdu);
  if (!pdu.ok()) {
    ++counters_.malformed;
    return true;
  }
  if (pdu.header.type != DcpServiceType::Request || e.frame_class == FrameClass::DcpHello ||
      e.frame_class == FrameClass::DcpIdentifyResponse) {
    ++counters_.ignored;
    return true;
  }
  if (e.frame_class == FrameClass::DcpIdentifyRequest) {
    if (e.header.dst != kDcpIdentifyMulticast && e.header.dst != mac_) {
      ++counters_.not_for_us;
    } else if (pdu.header.service != DcpService::Identify) {
      ++counters_.malformed;
    } else {
      on_identify(e, pdu, now);
    }
    return true;
  }
  // FEFDh: Get or Set, unicast.
  if (e.header.dst != mac_) {
    ++counters_.not_for_us;
  } else if (pdu.header.service == DcpService::Get) {
    on_get(e, pdu, now);
  } else if (pdu.header.service == DcpService::Set) {
    on_set(e, pdu, now);
  } else {
    ++counters_.malformed;
  }
  return true;
}

void DcpResponder::on_identify(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept {
  const DcpIdentifyFilter f = decode_identify_request(pdu);
  if (f.error != DcpError::None) {
    ++counters_.malformed;
    return;
  }
  if (f.other_filters > 0 || (f.all && f.has_name)) {
    ++counters_.identify_other_filter;
    return;
  }
  if (f.has_name && (name_length_ == 0 || f.name_of_station != name_of_station())) {
    ++counters_.identify_not_matched;
    return;
  }
  TxSlot* slot = reserve(now + response_delay(pdu.header.response_delay));
  if (slot == nullptr) return;
  const std::size_t n = encode_identify_response(pdu_area(slot->frame), pdu.header.xid, device_info());
  if (commit(*slot, e.header.src, frame_id::kDcpIdentifyResponse, n)) ++counters_.identify_answered;
}

bool DcpResponder::resend_if_retry(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept {
  if (!have_last_ || last_src_ != e.header.src || last_xid_ != pdu.header.xid || last_service_ != pdu.header.service) {
    return false;
  }
  if (TxSlot* slot = reserve(now)) {
    std::copy_n(last_frame_.begin(), last_length_, slot->frame.begin());
    slot->length = last_length_;
    slot->used = true;
    ++counters_.retries_answered;
  }
  return true;
}

void DcpResponder::remember(const EthernetView& e, const DcpPdu& pdu, const TxSlot& slot) noexcept {
  have_last_ = true;
  last_src_ = e.header.src;
  last_xid_ = pdu.header.xid;
  last_service_ = pdu.header.service;
  last_length_ = slot.length;
  std::copy_n(slot.frame.begin(), slot.length, last_frame_.begin());
}

void DcpResponder::on_get(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept {
  const DcpGetRequest g = decode_get_request(pdu);
  if (g.error != DcpError::None) {
    ++counters_.malformed;
    return;
  }
  if (resend_if_retry(e, pdu, now)) return;
  TxSlot* slot = reserve(now);
  if (slot == nullptr) return;
  ++counters_.gets;
  const DcpDeviceInfo d = device_info();
  DcpWriter w(pdu_area(slot->frame), DcpService::Get, DcpServiceType::ResponseSuccess, pdu.header.xid);
  for (std::size_t i = 0; i < g.count(); ++i) {
    const std::uint16_t id = g.option(i);
    switch (id) {
      case dcp_option::kMacAddress: w.add(id, 0, mac_); break;
      case dcp_option::kIpParameter: {
        std::array<std::uint8_t, 12> v{};
        std::copy(ip_.address.begin(), ip_.address.end(), v.begin());
        std::copy(ip_.netmask.begin(), ip_.netmask.end(), v.begin() + 4);
        std::copy(ip_.gateway.begin(), ip_.gateway.end(), v.begin() + 8);
        w.add(id, d.ip_block_info, v);
        break;
      }
      case dcp_option::kTypeOfStation: w.add(id, 0, d.type_of_station); break;
      case dcp_option::kNameOfStation: w.add(id, 0, d.name_of_station); break;
      case dcp_option::kDeviceId: {
        std::array<std::uint8_t, 4> v{};
        put_be16(v, 0, vendor_id_);
        put_be16(v, 2, device_id_);
        w.add(id, 0, v);
        break;
      }
      case dcp_option::kDeviceRole: w.add(id, 0, std::array<std::uint8_t, 2>{device_role_, 0}); break;
      case dcp_option::kDeviceOptions: w.add(id, 0, kOptionBytes); break;
      case dcp_option::kDeviceInstance: w.add(id, 0, std::array<std::uint8_t, 2>{instance_high_, instance_low_}); break;
      default: {
        const auto error = option_known(dcp_option::option_of(id)) ? DcpBlockError::SuboptionNotSupported
                                                                   : DcpBlockError::OptionNotSupported;
        const std::array<std::uint8_t, 3> v{dcp_option::option_of(id), dcp_option::suboption_of(id),
                                            static_cast<std::uint8_t>(error)};
        w.add_raw(dcp_option::kResponse, v);
        break;
      }
    }
  }
  if (commit(*slot, e.header.src, frame_id::kDcpGetSet, w.finish())) remember(e, pdu, *slot);
}

void DcpResponder::set_name(std::string_view name) noexcept {
  std::copy(name.begin(), name.end(), name_.begin());
  name_length_ = name.size();
}

DcpBlockError DcpResponder::apply(const DcpSetBlock& b) noexcept {
  const bool permanent = (b.qualifier & static_cast<std::uint16_t>(DcpQualifier::Permanent)) != 0;
  switch (b.id) {
    case dcp_option::kNameOfStation: {
      const std::string_view name = text_of(b.data);
      if (in_operation_) return DcpBlockError::InOperation;
      if (!name.empty() && validate_name_of_station(name) != NameError::None) return DcpBlockError::SuboptionNotSet;
      set_name(name);
      if (permanent) {
        stored_name_ = name_;
        stored_name_length_ = name_length_;
      } else {
        stored_name_length_ = 0;
      }
      return DcpBlockError::NoError;
    }
    case dcp_option::kIpParameter: {
      IpSuite ip;
      if (in_operation_) return DcpBlockError::InOperation;
      if (read_ip_suite(b.data, ip) != DcpError::None || !ip_suite_problem(ip).empty()) {
        return DcpBlockError::SuboptionNotSet;
      }
      ip_ = ip;
      stored_ip_ = permanent ? ip : IpSuite{};
      return DcpBlockError::NoError;
    }
    case dcp_option::kSignal:
      if (b.data.size() != 2 || get_be16(b.data, 0) != kDcpSignalFlashOnce) return DcpBlockError::SuboptionNotSet;
      ++counters_.signals;
      if (on_signal_) on_signal_();
      return DcpBlockError::NoError;
    case dcp_option::kStartTransaction:
    case dcp_option::kEndTransaction:
      return DcpBlockError::NoError;
    default:
      return option_known(dcp_option::option_of(b.id)) ? DcpBlockError::SuboptionNotSupported
                                                       : DcpBlockError::OptionNotSupported;
  }
}

void DcpResponder::on_set(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept {
  // Check the whole request before acting on any block.
  std::size_t blocks = 0;
  {
    DcpBlockReader r(pdu.blocks);
    DcpBlock b;
    DcpSetBlock s;
    bool bad = false;
    while (r.next(b)) {
      ++blocks;
      bad = bad || read_set_block(b, s) != DcpError::None;
    }
    if (bad || r.error() != DcpError::None || blocks == 0) {
      ++counters_.malformed;
      return;
    }
  }
  if (resend_if_retry(e, pdu, now)) return;
  TxSlot* slot = reserve(now);
  if (slot == nullptr) return;
  ++counters_.sets;
  DcpWriter w(pdu_area(slot->frame), DcpService::Set, DcpServiceType::ResponseSuccess, pdu.header.xid);
  DcpBlockReader r(pdu.blocks);
  DcpBlock b;
  while (r.next(b)) {
    DcpSetBlock s;
    (void)read_set_block(b, s);
    const DcpBlockError error = apply(s);
    if (error != DcpBlockError::NoError) ++counters_.set_errors;
    const std::array<std::uint8_t, 3> v{b.option, b.suboption, static_cast<std::uint8_t>(error)};
    w.add_raw(dcp_option::kResponse, v);
  }
  if (commit(*slot, e.header.src, frame_id::kDcpGetSet, w.finish())) remember(e, pdu, *slot);
}

std::size_t DcpResponder::poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept {
  TxSlot* first = nullptr;
  for (TxSlot& t : tx_) {
    if (t.used && t.due <= now && (first == nullptr || t.due < first->due)) first = &t;
  }
  if (first == nullptr) return 0;
  if (out.size() < first->length) {
    ++counters_.tx_too_small;
    return 0;
  }
  std::copy_n(first->frame.begin(), first->length, out.begin());
  first->used = false;
  return first->length;
}

core::TimePoint DcpResponder::next_deadline() const noexcept {
  core::TimePoint next = core::TimePoint::max();
  for (const TxSlot& t : tx_) {
    if (t.used) next = std::min(next, t.due);
  }
  return next;
}

}  // namespace drivegate::profinet
