#include "adapters/profinet/wire/rpc.hpp"

#include <algorithm>

namespace drivegate::profinet {

std::string_view to_string(PacketType t) noexcept {
  switch (t) {
    case PacketType::Request: return "request";
    case PacketType::Ping: return "ping";
    case PacketType::Response: return "response";
    case PacketType::Fault: return "fault";
    case PacketType::Working: return "working";
    case PacketType::Nocall: return "nocall";
    case PacketType::Reject: return "reject";
    case PacketType::Ack: return "ack";
    case PacketType::ClCancel: return "cl_cancel";
    case PacketType::Fack: return "fack";
    case PacketType::CancelAck: return "cancel_ack";
  }
  return "unknown";
}

std::string_view to_string(Opnum o) noexcept {
  switch (o) {
    case Opnum::Connect: return "Connect";
    case Opnum::Release: return "Release";
    case Opnum::Read: return "Read";
    case Opnum::Write: return "Write";
    case Opnum::Control: return "Control";
    case Opnum::ReadImplicit: return "ReadImplicit";
  }
  return "unknown";
}

Uuid make_pnio_object_uuid(const PnioObject& o) noexcept {
  Uuid u{0xDEA00000, 0x6C97, 0x11D1, {0x82, 0x71, 0, 0, 0, 0, 0, 0}};
  u.clock_seq_node[2] = static_cast<std::uint8_t>(o.instance >> 8);
  u.clock_seq_node[3] = static_cast<std::uint8_t>(o.instance & 0xFF);
  u.clock_seq_node[4] = static_cast<std::uint8_t>(o.device_id >> 8);
  u.clock_seq_node[5] = static_cast<std::uint8_t>(o.device_id & 0xFF);
  u.clock_seq_node[6] = static_cast<std::uint8_t>(o.vendor_id >> 8);
  u.clock_seq_node[7] = static_cast<std::uint8_t>(o.vendor_id & 0xFF);
  return u;
}

bool parse_pnio_object_uuid(const Uuid& u, PnioObject& out) noexcept {
  if (u.time_low != 0xDEA00000 || u.time_mid != 0x6C97 || u.time_hi_and_version != 0x11D1 ||
      u.clock_seq_node[0] != 0x82 || u.clock_seq_node[1] != 0x71) {
    return false;
  }
  const auto& n = u.clock_seq_node;
  out.instance = static_cast<std::uint16_t>((n[2] << 8) | n[3]);
  out.device_id = static_cast<std::uint16_t>((n[4] << 8) | n[5]);
  out.vendor_id = static_cast<std::uint16_t>((n[6] << 8) | n[7]);
  return true;
}

namespace {

std::uint8_t drep0(const RpcHeader& h) noexcept {
  return static_cast<std::uint8_t>(((h.order == ByteOrder::Little ? 1 : 0) << 4) | (h.drep_char & 0x0F));
}

void write_header(Writer& w, const RpcHeader& h) noexcept {
  w.u8(h.version);
  w.u8(h.packet_type);
  w.u8(h.flags1);
  w.u8(h.flags2);
  w.u8(drep0(h));
  w.u8(h.drep_float);
  w.u8(0);  // drep[2] reserved
  w.u8(h.serial_high);
  w.uuid(h.object);
  w.uuid(h.interface);
  w.uuid(h.activity);
  w.u32(h.server_boot_time);
  w.u32(h.interface_version);
  w.u32(h.sequence_number);
  w.u16(h.opnum);
  w.u16(h.interface_hint);
  w.u16(h.activity_hint);
  w.u16(h.fragment_length);
  w.u16(h.fragment_number);
  w.u8(h.auth_protocol);
  w.u8(h.serial_low);
}

}  // namespace

std::size_t encode_rpc_header(const RpcHeader& h, std::span<std::uint8_t> out) noexcept {
  if (h.drep_char != 0) return 0;  // only ASCII is spoken [DCE 1.1 RPC §14.2.5]
  Writer w(out, h.order);
  write_header(w, h);
  return w.size_or_zero();
}

RpcView decode_rpc(std::span<const std::uint8_t> in) noexcept {
  RpcView v;
  if (in.size() < kRpcHeaderSize) {
    v.error = WireError::Truncated;
    return v;
  }
  RpcHeader& h = v.header;
  h.version = in[0];
  h.packet_type = in[1];
  h.flags1 = in[2];
  h.flags2 = in[3];
  const std::uint8_t int_rep = static_cast<std::uint8_t>(in[4] >> 4);
  h.drep_char = static_cast<std::uint8_t>(in[4] & 0x0F);
  h.drep_float = in[5];
  h.serial_high = in[7];
  if (h.version != kRpcVersion) {
    v.error = WireError::BadRpcVersion;
    return v;
  }
  if (h.packet_type > static_cast<std::uint8_t>(PacketType::CancelAck)) {
    v.error = WireError::UnknownPacketType;
    return v;
  }
  // drep byte 0: integer representation in bits 4-7 (0 big, 1 little endian), character set in
  // bits 0-3 (0 ASCII, 1 EBCDIC) [DCE 1.1 RPC §14.2.5]. PNIO carries no RPC characters, but an
  // EBCDIC sender would be a stranger we do not want to answer.
  if (int_rep > 1 || h.drep_char != 0) {
    v.error = WireError::UnsupportedDrep;
    return v;
  }
  h.order = int_rep == 1 ? ByteOrder::Little : ByteOrder::Big;
  Reader r(in.subspan(8, kRpcHeaderSize - 8), h.order);
  h.object = r.uuid();
  h.interface = r.uuid();
  h.activity = r.uuid();
  h.server_boot_time = r.u32();
  h.interface_version = r.u32();
  h.sequence_number = r.u32();
  h.opnum = r.u16();
  h.interface_hint = r.u16();
  h.activity_hint = r.u16();
  h.fragment_length = r.u16();
  h.fragment_number = r.u16();
  h.auth_protocol = r.u8();
  h.serial_low = r.u8();
  if (h.fragment_length > in.size() - kRpcHeaderSize) {
    v.error = WireError::FragmentLengthBeyondData;
    return v;
  }
  v.body = in.subspan(kRpcHeaderSize, h.fragment_length);
  return v;
}

NdrRequestView decode_ndr_request(std::span<const std::uint8_t> body, ByteOrder order) noexcept {
  NdrRequestView v;
  Reader r(body, order);
  NdrRequest& n = v.ndr;
  n.args_maximum = r.u32();
  n.args_length = r.u32();
  n.maximum_count = r.u32();
  n.offset = r.u32();
  n.actual_count = r.u32();
  if (!r.ok()) {
    v.error = r.error();
    return v;
  }
  if (n.args_length > r.remaining()) {
    v.error = WireError::ArgsLengthBeyondData;
    return v;
  }
  // The blocks are an NDR conformant varying array of octets [DCE 1.1 RPC §14.3.3.4]: the actual
  // count is the byte count and lies within the maximum count from the offset on.
  if (n.actual_count != n.args_length || n.offset > n.maximum_count ||
      n.actual_count > n.maximum_count - n.offset || n.args_length > n.args_maximum) {
    v.error = WireError::NdrCountsInconsistent;
    return v;
  }
  n.blocks = r.bytes(n.args_length);
  return v;
}

NdrResponseView decode_ndr_response(std::span<const std::uint8_t> body, ByteOrder order) noexcept {
  NdrResponseView v;
  Reader r(body, order);
  NdrResponse& n = v.ndr;
  // In the NDR part PNIOStatus is marshalled as one Unsigned32 (ErrorCode in the most significant
  // octet), so a little-endian drep reverses the four octets; inside the big-endian blocks it reads
  // in field order [IEC 61158-6-10 §5.1.2 IDL "PNIOStatus", §5.2.6].
  n.status = status_from_u32(r.u32());
  n.args_length = r.u32();
  n.maximum_count = r.u32();
  n.offset = r.u32();
  n.actual_count = r.u32();
  if (!r.ok()) {
    v.error = r.error();
    return v;
  }
  if (n.args_length > r.remaining()) {
    v.error = WireError::ArgsLengthBeyondData;
    return v;
  }
  if (n.actual_count != n.args_length || n.offset > n.maximum_count || n.actual_count > n.maximum_count - n.offset) {
    v.error = WireError::NdrCountsInconsistent;
    return v;
  }
  n.blocks = r.bytes(n.args_length);
  return v;
}

std::size_t finish_pnio_request(RpcHeader h, std::uint32_t args_maximum, std::size_t blocks_length,
                                std::span<std::uint8_t> out) noexcept {
  if (blocks_length > args_maximum || kNdrHeaderSize + blocks_length > 0xFFFF) return 0;
  if (out.size() < kPnioBlocksOffset + blocks_length) return 0;
  h.fragment_length = static_cast<std::uint16_t>(kNdrHeaderSize + blocks_length);
  if (encode_rpc_header(h, out) == 0) return 0;
  Writer w(out.subspan(kRpcHeaderSize, kNdrHeaderSize), h.order);
  const auto len = static_cast<std::uint32_t>(blocks_length);
  w.u32(args_maximum);
  w.u32(len);
  w.u32(args_maximum);
  w.u32(0);
  w.u32(len);
  return w.ok() ? kPnioBlocksOffset + blocks_length : 0;
}

std::size_t finish_pnio_response(RpcHeader h, const PnioStatus& status, std::uint32_t maximum_count,
                                 std::size_t blocks_length, std::span<std::uint8_t> out) noexcept {
  if (blocks_length > maximum_count || kNdrHeaderSize + blocks_length > 0xFFFF) return 0;
  if (out.size() < kPnioBlocksOffset + blocks_length) return 0;
  h.fragment_length = static_cast<std::uint16_t>(kNdrHeaderSize + blocks_length);
  if (encode_rpc_header(h, out) == 0) return 0;
  Writer w(out.subspan(kRpcHeaderSize, kNdrHeaderSize), h.order);
  const auto len = static_cast<std::uint32_t>(blocks_length);
  w.u32(status_to_u32(status));
  w.u32(len);
  w.u32(maximum_count);
  w.u32(0);
  w.u32(len);
  return w.ok() ? kPnioBlocksOffset + blocks_length : 0;
}

RpcHeader response_header_for(const RpcHeader& request, std::uint32_t server_boot_time) noexcept {
  RpcHeader h = request;
  h.packet_type = static_cast<std::uint8_t>(PacketType::Response);
  h.flags1 = rpc_flag1::kLastFragment | rpc_flag1::kNoFack;
  h.flags2 = 0;
  h.server_boot_time = server_boot_time;
  h.interface_hint = 0xFFFF;
  h.activity_hint = 0xFFFF;
  h.fragment_length = 0;
  h.fragment_number = 0;
  return h;
}

RpcFaultView decode_rpc_fault(std::span<const std::uint8_t> body, ByteOrder order) noexcept {
  RpcFaultView v;
  Reader r(body, order);
  v.status = r.u32();
  v.error = r.error();
  return v;
}

std::size_t encode_rpc_fault(RpcHeader h, PacketType type, std::uint32_t status, std::span<std::uint8_t> out) noexcept {
  if (type != PacketType::Fault && type != PacketType::Reject) return 0;
  h.packet_type = static_cast<std::uint8_t>(type);
  h.fragment_length = 4;
  if (encode_rpc_header(h, out) == 0) return 0;
  Writer w(out.subspan(kRpcHeaderSize), h.order);
  w.u32(status);
  return w.ok() ? kRpcHeaderSize + 4 : 0;
}

std::string_view nca_status_text(std::uint32_t status) noexcept {
  // [DCE 1.1 RPC Appendix E "Reject Status Codes"]: the ones a PNIO peer answers with.
  switch (status) {
    case 0x1C010001: return "nca_s_comm_failure: communication failure";
    case 0x1C010002: return "nca_s_op_rng_error: operation number out of range";
    case 0x1C010003: return "nca_s_unk_if: unknown interface";
    case 0x1C010006: return "nca_s_wrong_boot_time: server boot time changed";
    case 0x1C010009: return "nca_s_you_crashed: the server rebooted";
    case 0x1C01000B: return "nca_s_proto_error: protocol error";
    case 0x1C010013: return "nca_s_out_args_too_big: response larger than ArgsMaximum";
    case 0x1C010014: return "nca_s_server_too_busy";
    case 0x1C010017: return "nca_s_unsupported_type";
    case 0x1C000008: return "nca_s_fault_invalid_tag";
    case 0x1C000009: return "nca_s_fault_invalid_bound";
    case 0x1C00000C: return "nca_s_fault_cancel";
    case 0x1C000011: return "nca_s_fault_remote_no_memory";
    case 0x1C000012: return "nca_s_fault_context_mismatch";
    case 0x1C00001C: return "nca_s_fault_unspec: unspecified fault";
    default: return "unknown NCA status";
  }
}

}  // namespace drivegate::profinet
