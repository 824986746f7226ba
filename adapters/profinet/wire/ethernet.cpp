#include "adapters/profinet/wire/ethernet.hpp"

#include <algorithm>

#include "adapters/profinet/wire/byte_order.hpp"

namespace drivegate::profinet {

FrameClass classify_frame_id(std::uint16_t id) noexcept {
  if (id >= frame_id::kRtClass1First && id <= frame_id::kRtClass1MulticastLast) return FrameClass::RtCyclic;
  switch (id) {
    case frame_id::kAlarmHigh: return FrameClass::AlarmHigh;
    case frame_id::kAlarmLow: return FrameClass::AlarmLow;
    case frame_id::kDcpHello: return FrameClass::DcpHello;
    case frame_id::kDcpGetSet: return FrameClass::DcpGetSet;
    case frame_id::kDcpIdentifyRequest: return FrameClass::DcpIdentifyRequest;
    case frame_id::kDcpIdentifyResponse: return FrameClass::DcpIdentifyResponse;
    default: return FrameClass::Other;
  }
}

std::string_view to_string(FrameClass c) noexcept {
  switch (c) {
    case FrameClass::Other: return "other FrameID";
    case FrameClass::RtCyclic: return "RT class 1 cyclic";
    case FrameClass::AlarmHigh: return "alarm high";
    case FrameClass::AlarmLow: return "alarm low";
    case FrameClass::DcpHello: return "DCP hello";
    case FrameClass::DcpGetSet: return "DCP get/set";
    case FrameClass::DcpIdentifyRequest: return "DCP identify request";
    case FrameClass::DcpIdentifyResponse: return "DCP identify response";
  }
  return "?";
}

std::size_t encode_ethernet_header(const EthernetHeader& h, std::span<std::uint8_t> out) noexcept {
  const std::size_t size = kEthernetHeaderSize + (h.vlan ? kVlanTagSize : 0) + kFrameIdSize;
  if (out.size() < size || h.priority > 7 || h.vlan_id > 0x0FFF) return 0;
  std::copy(h.dst.begin(), h.dst.end(), out.begin());
  std::copy(h.src.begin(), h.src.end(), out.begin() + 6);
  std::size_t at = 12;
  if (h.vlan) {
    put_be16(out, at, kVlanTpid);
    put_be16(out, at + 2, static_cast<std::uint16_t>((h.priority << 13) | h.vlan_id));
    at += kVlanTagSize;
  }
  put_be16(out, at, kEtherType);
  put_be16(out, at + 2, h.frame_id);
  return size;
}

std::size_t pad_frame(std::span<std::uint8_t> out, std::size_t used) noexcept {
  const std::size_t size = std::max(used, kMinFrameSize);
  if (used > out.size() || size > out.size()) return 0;
  std::fill(out.begin() + static_cast<std::ptrdiff_t>(used), out.begin() + static_cast<std::ptrdiff_t>(size),
            std::uint8_t{0});
  return size;
}

std::string_view to_string(EthernetError e) noexcept {
  switch (e) {
    case EthernetError::None: return "no error";
    case EthernetError::TruncatedHeader: return "frame shorter than its Ethernet header";
    case EthernetError::WrongEtherType: return "EtherType is not 8892h (PROFINET)";
    case EthernetError::TruncatedFrameId: return "frame ends before the FrameID";
    case EthernetError::TooLong: return "frame longer than 1518 octets";
  }
  return "?";
}

EthernetView decode_ethernet(std::span<const std::uint8_t> frame) noexcept {
  EthernetView v;
  if (frame.size() > kMaxFrameSize) {
    v.error = EthernetError::TooLong;
    return v;
  }
  if (frame.size() < kEthernetHeaderSize) {
    v.error = EthernetError::TruncatedHeader;
    return v;
  }
  std::copy(frame.begin(), frame.begin() + 6, v.header.dst.begin());
  std::copy(frame.begin() + 6, frame.begin() + 12, v.header.src.begin());
  std::size_t at = 12;
  std::uint16_t type = get_be16(frame, at);
  if (type == kVlanTpid) {
    if (frame.size() < kEthernetHeaderSize + kVlanTagSize) {
      v.error = EthernetError::TruncatedHeader;
      return v;
    }
    const std::uint16_t tci = get_be16(frame, at + 2);
    v.header.vlan = true;
    v.header.priority = static_cast<std::uint8_t>(tci >> 13);
    v.header.vlan_id = static_cast<std::uint16_t>(tci & 0x0FFF);
    at += kVlanTagSize;
    type = get_be16(frame, at);
  }
  if (type != kEtherType) {
    v.error = EthernetError::WrongEtherType;
    return v;
  }
  at += 2;
  if (frame.size() < at + kFrameIdSize) {
    v.error = EthernetError::TruncatedFrameId;
    return v;
  }
  v.header.frame_id = get_be16(frame, at);
  v.frame_class = classify_frame_id(v.header.frame_id);
  v.pdu_offset = at + kFrameIdSize;
  v.pdu = frame.subspan(v.pdu_offset);
  return v;
}

std::array<char, 18> mac_text(const MacAddress& mac) noexcept {
  static constexpr char kHex[] = "0123456789abcdef";
  std::array<char, 18> t{};
  for (std::size_t i = 0; i < mac.size(); ++i) {
    t[3 * i] = kHex[mac[i] >> 4];
    t[3 * i + 1] = kHex[mac[i] & 0x0F];
    t[3 * i + 2] = i + 1 < mac.size() ? ':' : '\0';
  }
  return t;
}

std::optional<MacAddress> parse_mac(std::string_view text) noexcept {
  if (text.size() != 17 || (text[2] != ':' && text[2] != '-')) return std::nullopt;
  const auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  MacAddress mac{};
  for (std::size_t i = 0; i < mac.size(); ++i) {
    const int high = nibble(text[3 * i]), low = nibble(text[3 * i + 1]);
    if (high < 0 || low < 0 || (i + 1 < mac.size() && text[3 * i + 2] != text[2])) return std::nullopt;
    mac[i] = static_cast<std::uint8_t>(high << 4 | low);
  }
  return mac;
}

}  // namespace drivegate::profinet
