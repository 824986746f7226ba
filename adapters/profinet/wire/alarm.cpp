#include "adapters/profinet/wire/alarm.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "adapters/profinet/wire/byte_order.hpp"
#include "adapters/profinet/wire/ethernet.hpp"

namespace drivegate::profinet {

namespace {

constexpr std::size_t kBlockHeader = 6;  // BlockType, BlockLength, BlockVersionHigh, BlockVersionLow
// The RTA-SDU of one frame: 1500 payload octets - FrameID - RTA header.
constexpr std::size_t kMaxVarPart = kMaxPayloadSize - kFrameIdSize - kRtaHeaderSize;

void put_block_header(std::span<std::uint8_t> out, std::uint16_t type, std::size_t total) noexcept {
  put_be16(out, 0, type);
  put_be16(out, 2, static_cast<std::uint16_t>(total - 4));  // BlockLength counts from the version on
  out[4] = 1;  // BlockVersionHigh
  out[5] = 0;  // BlockVersionLow
}

// Checks the BlockHeader of the one block a DATA var part holds; `fixed` is the block's minimum
// size including the header. On success `type` is the BlockType and the block spans the var part.
AlarmError check_block(std::span<const std::uint8_t> in, std::size_t fixed, std::uint16_t high, std::uint16_t low,
                       std::uint16_t& type) noexcept {
  if (in.size() < kBlockHeader) return AlarmError::TruncatedBlockHeader;
  type = get_be16(in, 0);
  if (type != high && type != low) return AlarmError::WrongBlockType;
  if (in[4] != 1 || in[5] != 0) return AlarmError::UnsupportedBlockVersion;
  const std::size_t total = 4U + get_be16(in, 2);
  if (total < fixed || total != in.size()) return AlarmError::BlockLengthMismatch;
  return AlarmError::None;
}

}  // namespace

std::string_view to_string(RtaPduType t) noexcept {
  switch (t) {
    case RtaPduType::Data: return "DATA-RTA-PDU";
    case RtaPduType::Nack: return "NACK-RTA-PDU";
    case RtaPduType::Ack: return "ACK-RTA-PDU";
    case RtaPduType::Err: return "ERR-RTA-PDU";
  }
  return "?";
}

std::string_view to_string(AlarmError e) noexcept {
  switch (e) {
    case AlarmError::None: return "no error";
    case AlarmError::TruncatedRtaHeader: return "RTA-PDU shorter than its 12-octet header";
    case AlarmError::VarPartBeyondPdu: return "VarPartLen runs past the end of the frame";
    case AlarmError::UnknownPduType: return "unknown RTA PDUType";
    case AlarmError::UnsupportedVersion: return "RTA PDUType version is not 1";
    case AlarmError::UnexpectedVarPart: return "VarPartLen does not fit the PDU type (ACK/NACK empty, ERR a PNIOStatus, DATA a block)";
    case AlarmError::TruncatedBlockHeader: return "alarm block shorter than its BlockHeader";
    case AlarmError::WrongBlockType: return "alarm block type is not the one expected";
    case AlarmError::UnsupportedBlockVersion: return "alarm block version is not 1.0";
    case AlarmError::BlockLengthMismatch: return "alarm BlockLength does not match the octets of the block";
    case AlarmError::BufferTooSmall: return "buffer too small for the alarm PDU";
    case AlarmError::DataTooLong: return "alarm data longer than one frame can carry";
    case AlarmError::NotChannelDiagnosis: return "the alarm item is not channel diagnosis (USI 8000h, 8002h, 8003h)";
    case AlarmError::ChannelDiagnosisLength: return "channel diagnosis data is not a whole number of entries";
  }
  return "?";
}

bool encode_rta_header(const RtaHeader& h, std::span<std::uint8_t> out) noexcept {
  if (out.size() < kRtaHeaderSize || h.version > 15 || h.window_size > 15) return false;
  put_be16(out, 0, h.dst_endpoint);
  put_be16(out, 2, h.src_endpoint);
  out[4] = static_cast<std::uint8_t>((h.version << 4) | (static_cast<std::uint8_t>(h.type) & 0x0F));
  out[5] = static_cast<std::uint8_t>((h.tack ? 0x10 : 0x00) | h.window_size);
  put_be16(out, 6, h.send_seq);
  put_be16(out, 8, h.ack_seq);
  put_be16(out, 10, h.var_part_len);
  return true;
}

std::size_t encode_rta(std::span<std::uint8_t> out, RtaHeader h, std::span<const std::uint8_t> var_part) noexcept {
  if (var_part.size() > kMaxVarPart || out.size() < kRtaHeaderSize + var_part.size()) return 0;
  h.var_part_len = static_cast<std::uint16_t>(var_part.size());
  // The var part may have been written in place behind the header already: memmove.
  if (!var_part.empty()) std::memmove(out.data() + kRtaHeaderSize, var_part.data(), var_part.size());
  if (!encode_rta_header(h, out)) return 0;
  return kRtaHeaderSize + var_part.size();
}

RtaView decode_rta(std::span<const std::uint8_t> pdu) noexcept {
  RtaView v;
  if (pdu.size() < kRtaHeaderSize) {
    v.error = AlarmError::TruncatedRtaHeader;
    return v;
  }
  RtaHeader& h = v.header;
  h.dst_endpoint = get_be16(pdu, 0);
  h.src_endpoint = get_be16(pdu, 2);
  const std::uint8_t type = pdu[4] & 0x0F;
  h.type = static_cast<RtaPduType>(type);
  h.version = static_cast<std::uint8_t>(pdu[4] >> 4);
  h.window_size = pdu[5] & 0x0F;
  h.tack = (pdu[5] & 0x10) != 0;
  h.send_seq = get_be16(pdu, 6);
  h.ack_seq = get_be16(pdu, 8);
  h.var_part_len = get_be16(pdu, 10);
  if (type < 1 || type > 4) {
    v.error = AlarmError::UnknownPduType;
    return v;
  }
  if (h.version != kRtaVersion) {
    v.error = AlarmError::UnsupportedVersion;
    return v;
  }
  if (h.var_part_len > pdu.size() - kRtaHeaderSize) {
    v.error = AlarmError::VarPartBeyondPdu;
    return v;
  }
  const bool fits = (h.type == RtaPduType::Data && h.var_part_len > 0) ||
                    ((h.type == RtaPduType::Ack || h.type == RtaPduType::Nack) && h.var_part_len == 0) ||
                    (h.type == RtaPduType::Err && h.var_part_len >= 4);
  if (!fits) {
    v.error = AlarmError::UnexpectedVarPart;
    return v;
  }
  v.var_part = pdu.subspan(kRtaHeaderSize, h.var_part_len);
  return v;
}

RtaPnioStatus rta_error_status(const RtaView& v) noexcept {
  RtaPnioStatus s;
  if (v.var_part.size() >= 4) {
    s.code = v.var_part[0];
    s.decode = v.var_part[1];
    s.code1 = v.var_part[2];
    s.code2 = v.var_part[3];
  }
  return s;
}

std::size_t encode_rta_error(std::span<std::uint8_t> out, RtaHeader h, const RtaPnioStatus& status) noexcept {
  const std::array<std::uint8_t, 4> v{status.code, status.decode, status.code1, status.code2};
  h.type = RtaPduType::Err;
  return encode_rta(out, h, v);
}

// ---- Alarm blocks -----------------------------------------------------------------------------

const char* to_string(AlarmPriority p) noexcept { return p == AlarmPriority::High ? "high" : "low"; }

std::string_view alarm_type_name(std::uint16_t type) noexcept {
  switch (type) {
    case alarm_type::kDiagnosis: return "Diagnosis";
    case alarm_type::kProcess: return "Process";
    case alarm_type::kPull: return "Pull";
    case alarm_type::kPlug: return "Plug";
    case alarm_type::kStatus: return "Status";
    case alarm_type::kUpdate: return "Update";
    case alarm_type::kRedundancy: return "Media redundancy";
    case alarm_type::kControlledBySupervisor: return "Controlled by supervisor";
    case alarm_type::kReleasedBySupervisor: return "Released by supervisor";
    case alarm_type::kPlugWrongSubmodule: return "Plug wrong submodule";
    case alarm_type::kReturnOfSubmodule: return "Return of submodule";
    case alarm_type::kDiagnosisDisappears: return "Diagnosis disappears";
    case alarm_type::kMulticastMismatch: return "Multicast communication mismatch";
    case alarm_type::kPortDataChange: return "Port data change";
    case alarm_type::kSyncDataChanged: return "Sync data changed";
    case alarm_type::kIsochronousModeProblem: return "Isochronous mode problem";
    case alarm_type::kNetworkComponentProblem: return "Network component problem";
    case alarm_type::kTimeDataChanged: return "Time data changed";
    case alarm_type::kDynamicFramePackingProblem: return "Dynamic frame packing problem";
    case alarm_type::kUploadAndRetrieval: return "Upload and retrieval";
    case alarm_type::kPullModule: return "Pull module";
    default: break;
  }
  if (type >= 0x0020 && type <= 0x007F) return "manufacturer specific";
  if (type >= 0x0080 && type <= 0x00FF) return "reserved for profiles";
  return "reserved";
}

std::string_view user_structure_name(std::uint16_t usi) noexcept {
  switch (usi) {
    case user_structure::kChannelDiagnosis: return "ChannelDiagnosis";
    case user_structure::kMultiple: return "Multiple";
    case user_structure::kExtChannelDiagnosis: return "ExtChannelDiagnosis";
    case user_structure::kQualifiedChannelDiagnosis: return "QualifiedChannelDiagnosis";
    case user_structure::kMaintenance: return "Maintenance";
    default: break;
  }
  return usi < 0x8000 ? "manufacturer specific" : "reserved";
}

std::uint16_t encode_alarm_specifier(const AlarmSpecifier& s) noexcept {
  std::uint16_t v = s.sequence & 0x07FF;
  if (s.channel_diagnosis) v |= 0x0800;
  if (s.manufacturer_diagnosis) v |= 0x1000;
  if (s.submodule_diagnosis) v |= 0x2000;
  if (s.ar_diagnosis) v |= 0x8000;
  return v;
}

AlarmSpecifier decode_alarm_specifier(std::uint16_t raw) noexcept {
  AlarmSpecifier s;
  s.sequence = raw & 0x07FF;
  s.channel_diagnosis = (raw & 0x0800) != 0;
  s.manufacturer_diagnosis = (raw & 0x1000) != 0;
  s.submodule_diagnosis = (raw & 0x2000) != 0;
  s.ar_diagnosis = (raw & 0x8000) != 0;
  return s;
}

std::size_t encode_alarm_notification(std::span<std::uint8_t> out, const AlarmNotification& n) noexcept {
  const std::size_t total =
      kAlarmNotificationFixedSize + (n.has_user_structure ? 2 + n.user_data.size() : 0);
  if (total > kMaxVarPart || (!n.has_user_structure && !n.user_data.empty())) return 0;
  if (out.size() < total) return 0;
  put_block_header(out, n.priority == AlarmPriority::High ? alarm_block::kNotificationHigh : alarm_block::kNotificationLow,
                   total);
  put_be16(out, 6, n.alarm_type);
  put_be32(out, 8, n.api);
  put_be16(out, 12, n.slot);
  put_be16(out, 14, n.subslot);
  put_be32(out, 16, n.module_ident);
  put_be32(out, 20, n.submodule_ident);
  put_be16(out, 24, encode_alarm_specifier(n.specifier));
  if (n.has_user_structure) {
    put_be16(out, 26, n.user_structure_id);
    std::copy(n.user_data.begin(), n.user_data.end(), out.begin() + 28);
  }
  return total;
}

AlarmNotificationView decode_alarm_notification(std::span<const std::uint8_t> in) noexcept {
  AlarmNotificationView v;
  std::uint16_t type = 0;
  v.error = check_block(in, kAlarmNotificationFixedSize, alarm_block::kNotificationHigh, alarm_block::kNotificationLow,
                        type);
  if (v.error != AlarmError::None) return v;
  // One octet after the fixed part cannot be a UserStructureIdentifier.
  if (in.size() == kAlarmNotificationFixedSize + 1) {
    v.error = AlarmError::BlockLengthMismatch;
    return v;
  }
  AlarmNotification& n = v.notification;
  n.priority = type == alarm_block::kNotificationHigh ? AlarmPriority::High : AlarmPriority::Low;
  n.alarm_type = get_be16(in, 6);
  n.api = get_be32(in, 8);
  n.slot = get_be16(in, 12);
  n.subslot = get_be16(in, 14);
  n.module_ident = get_be32(in, 16);
  n.submodule_ident = get_be32(in, 20);
  n.specifier = decode_alarm_specifier(get_be16(in, 24));
  if (in.size() >= kAlarmNotificationFixedSize + 2) {
    n.has_user_structure = true;
    n.user_structure_id = get_be16(in, 26);
    n.user_data = in.subspan(28);
  }
  return v;
}

AlarmAck ack_for(const AlarmNotification& n, const RtaPnioStatus& status) noexcept {
  AlarmAck a;
  a.priority = n.priority;
  a.alarm_type = n.alarm_type;
  a.api = n.api;
  a.slot = n.slot;
  a.subslot = n.subslot;
  a.specifier = n.specifier;
  a.status = status;
  return a;
}

std::size_t encode_alarm_ack(std::span<std::uint8_t> out, const AlarmAck& a) noexcept {
  if (out.size() < kAlarmAckSize) return 0;
  put_block_header(out, a.priority == AlarmPriority::High ? alarm_block::kAckHigh : alarm_block::kAckLow, kAlarmAckSize);
  put_be16(out, 6, a.alarm_type);
  put_be32(out, 8, a.api);
  put_be16(out, 12, a.slot);
  put_be16(out, 14, a.subslot);
  put_be16(out, 16, encode_alarm_specifier(a.specifier));
  out[18] = a.status.code;
  out[19] = a.status.decode;
  out[20] = a.status.code1;
  out[21] = a.status.code2;
  return kAlarmAckSize;
}

AlarmAckView decode_alarm_ack(std::span<const std::uint8_t> in) noexcept {
  AlarmAckView v;
  std::uint16_t type = 0;
  v.error = check_block(in, kAlarmAckSize, alarm_block::kAckHigh, alarm_block::kAckLow, type);
  if (v.error != AlarmError::None) return v;
  if (in.size() != kAlarmAckSize) {
    v.error = AlarmError::BlockLengthMismatch;
    return v;
  }
  AlarmAck& a = v.ack;
  a.priority = type == alarm_block::kAckHigh ? AlarmPriority::High : AlarmPriority::Low;
  a.alarm_type = get_be16(in, 6);
  a.api = get_be32(in, 8);
  a.slot = get_be16(in, 12);
  a.subslot = get_be16(in, 14);
  a.specifier = decode_alarm_specifier(get_be16(in, 16));
  a.status = RtaPnioStatus{in[18], in[19], in[20], in[21]};
  return v;
}

ChannelDiagnosisList decode_channel_diagnosis(std::uint16_t user_structure_id, std::span<const std::uint8_t> data) noexcept {
  ChannelDiagnosisList l;
  l.user_structure_id = user_structure_id;
  switch (user_structure_id) {
    case user_structure::kChannelDiagnosis: l.entry_size = 6; break;
    case user_structure::kExtChannelDiagnosis: l.entry_size = 12; break;
    case user_structure::kQualifiedChannelDiagnosis: l.entry_size = 16; break;
    default: l.error = AlarmError::NotChannelDiagnosis; return l;
  }
  if (data.empty() || data.size() % l.entry_size != 0) {
    l.error = AlarmError::ChannelDiagnosisLength;
    l.entry_size = 0;
    return l;
  }
  l.data = data;
  return l;
}

bool ChannelDiagnosisList::get(std::size_t i, ChannelDiagnosis& out) const noexcept {
  if (i >= count()) return false;
  const auto e = data.subspan(i * entry_size, entry_size);
  out = ChannelDiagnosis{};
  out.channel = get_be16(e, 0);
  out.properties = get_be16(e, 2);
  out.error_type = get_be16(e, 4);
  if (entry_size >= 12) {
    out.ext_error_type = get_be16(e, 6);
    out.ext_add_value = get_be32(e, 8);
  }
  if (entry_size >= 16) out.qualifier = get_be32(e, 12);
  return true;
}

std::string_view channel_error_type_name(std::uint16_t type) noexcept {
  // The codes public references agree on (0013h is named differently by them and left out).
  switch (type) {
    case 0x0001: return "short circuit";
    case 0x0002: return "undervoltage";
    case 0x0003: return "overvoltage";
    case 0x0004: return "overload";
    case 0x0005: return "overtemperature";
    case 0x0006: return "line break";
    case 0x0007: return "upper limit value exceeded";
    case 0x0008: return "lower limit value exceeded";
    case 0x0009: return "error";
    case 0x000A: return "simulation active";
    case 0x000F: return "parameter missing";
    case 0x0010: return "parameterization fault";
    case 0x0011: return "power supply fault";
    case 0x0012: return "fuse blown / open";
    case 0x0014: return "ground fault";
    case 0x0015: return "reference point lost";
    case 0x0016: return "process event lost / sampling error";
    case 0x0017: return "threshold warning";
    case 0x0018: return "output disabled";
    case 0x0019: return "functional safety event";
    case 0x001A: return "external fault";
    case 0x001F: return "temporary fault";
    case 0x8000: return "data transmission impossible";
    case 0x8001: return "remote mismatch";
    case 0x8002: return "media redundancy mismatch";
    case 0x8003: return "sync mismatch";
    case 0x8004: return "isochronous mode mismatch";
    case 0x8005: return "multicast CR mismatch";
    default: break;
  }
  if (type >= 0x0100 && type <= 0x7FFF) return "manufacturer specific";
  return "reserved";
}

std::uint16_t alarm_block_type(std::span<const std::uint8_t> var_part) noexcept {
  return var_part.size() >= 2 ? get_be16(var_part, 0) : 0;
}

}  // namespace drivegate::profinet
