#include "adapters/profinet/wire/blocks.hpp"

#include <algorithm>
#include <array>

namespace drivegate::profinet {

std::string_view block_type_name(std::uint16_t type) noexcept {
  switch (type) {
    case block_type::kWriteReqHeader: return "IODWriteReqHeader";
    case block_type::kReadReqHeader: return "IODReadReqHeader";
    case block_type::kIm0: return "I&M0";
    case block_type::kIm1: return "I&M1";
    case block_type::kArBlockReq: return "ARBlockReq";
    case block_type::kIocrBlockReq: return "IOCRBlockReq";
    case block_type::kAlarmCrBlockReq: return "AlarmCRBlockReq";
    case block_type::kExpectedSubmoduleBlockReq: return "ExpectedSubmoduleBlockReq";
    case block_type::kPrmEndReq: return "IODControlReq (PrmEnd)";
    case block_type::kApplicationReadyReq: return "IOXControlReq (ApplicationReady)";
    case block_type::kReleaseReq: return "IODReleaseReq";
    case block_type::kWriteResHeader: return "IODWriteResHeader";
    case block_type::kReadResHeader: return "IODReadResHeader";
    case block_type::kArBlockRes: return "ARBlockRes";
    case block_type::kIocrBlockRes: return "IOCRBlockRes";
    case block_type::kAlarmCrBlockRes: return "AlarmCRBlockRes";
    case block_type::kModuleDiffBlock: return "ModuleDiffBlock";
    case block_type::kPrmEndRes: return "IODControlRes (PrmEnd)";
    case block_type::kApplicationReadyRes: return "IOXControlRes (ApplicationReady)";
    case block_type::kReleaseRes: return "IODReleaseRes";
    default: return "unknown block";
  }
}

BlockView decode_block(std::span<const std::uint8_t> in) noexcept {
  BlockView v;
  Reader r(in, ByteOrder::Big);
  v.header.type = r.u16();
  v.header.length = r.u16();
  v.header.version_high = r.u8();
  v.header.version_low = r.u8();
  if (!r.ok()) {
    v.error = WireError::Truncated;
    return v;
  }
  if (v.header.length < 2) {
    v.error = WireError::BlockLengthTooShort;
    return v;
  }
  if (v.header.length > in.size() - 4) {
    v.error = WireError::BlockLengthBeyondData;
    return v;
  }
  v.block = in.first(4 + std::size_t{v.header.length});
  v.body = v.block.subspan(kBlockHeaderSize);
  return v;
}

bool BlockWalker::next(BlockView& out) noexcept {
  if (error_ != WireError::None || rest_.empty()) return false;
  out = decode_block(rest_);
  if (out.error != WireError::None) {
    error_ = out.error;
    return false;
  }
  rest_ = rest_.subspan(out.block.size());
  return true;
}

std::size_t begin_block(Writer& w, std::uint16_t type, std::uint8_t version_low) noexcept {
  const std::size_t start = w.position();
  w.u16(type);
  w.u16(0);
  w.u8(1);
  w.u8(version_low);
  return start;
}

void end_block(Writer& w, std::size_t start) noexcept {
  if (!w.ok()) return;
  const std::size_t length = w.position() - start - 4;
  if (length > 0xFFFF) {
    w.fail(WireError::InvalidArgument);
    return;
  }
  w.patch_u16(start + 2, static_cast<std::uint16_t>(length));
}

BlockBody open_block_of(std::span<const std::uint8_t> in, std::span<const std::uint16_t> types,
                        std::size_t body_min) noexcept {
  BlockBody b;
  const BlockView v = decode_block(in);
  b.header = v.header;
  if (v.error != WireError::None) {
    b.error = v.error;
    return b;
  }
  if (std::find(types.begin(), types.end(), v.header.type) == types.end()) {
    b.error = WireError::WrongBlockType;
    return b;
  }
  if (v.header.version_high != 1) {
    b.error = WireError::UnsupportedBlockVersion;
    return b;
  }
  if (v.body.size() < body_min) {
    b.error = WireError::BlockLengthTooShort;
    return b;
  }
  b.body = v.body;
  b.size = v.block.size();
  return b;
}

BlockBody open_block(std::span<const std::uint8_t> in, std::uint16_t type, std::size_t body_min) noexcept {
  const std::array<std::uint16_t, 1> types{type};
  return open_block_of(in, types, body_min);
}

WireError finish_block(const Reader& r) noexcept {
  // open_block checked the fixed part, so running out of bytes means a count or a length field
  // inside the block promised more than BlockLength holds.
  if (r.error() == WireError::Truncated) return WireError::CountBeyondData;
  if (!r.ok()) return r.error();
  return r.remaining() == 0 ? WireError::None : WireError::BlockLengthMismatch;
}

// ---- AR ----------------------------------------------------------------------------------------

namespace {
// ARType .. StationNameLength [IEC 61158-6-10 §5.2.2.1 ARBlockReq]
constexpr std::size_t kArReqFixed = 2 + 16 + 2 + 6 + 16 + 4 + 2 + 2 + 2;
}  // namespace

std::size_t encode_ar_block_req(const ArBlockReq& b, std::span<std::uint8_t> out) noexcept {
  if (b.station_name.empty() || b.station_name.size() > kMaxStationNameLength) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kArBlockReq);
  w.u16(b.ar_type);
  w.uuid(b.ar_uuid);
  w.u16(b.session_key);
  w.mac(b.initiator_mac);
  w.uuid(b.initiator_object_uuid);
  w.u32(b.properties);
  w.u16(b.activity_timeout_factor);
  w.u16(b.udp_rt_port);
  w.u16(static_cast<std::uint16_t>(b.station_name.size()));
  w.text(b.station_name);
  end_block(w, start);
  return w.size_or_zero();
}

ArBlockReqView decode_ar_block_req(std::span<const std::uint8_t> in) noexcept {
  ArBlockReqView v;
  const BlockBody bb = open_block(in, block_type::kArBlockReq, kArReqFixed);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  ArBlockReq& b = v.block;
  b.ar_type = r.u16();
  b.ar_uuid = r.uuid();
  b.session_key = r.u16();
  b.initiator_mac = r.mac();
  b.initiator_object_uuid = r.uuid();
  b.properties = r.u32();
  b.activity_timeout_factor = r.u16();
  b.udp_rt_port = r.u16();
  const std::uint16_t name_length = r.u16();
  const auto name = r.bytes(name_length);
  b.station_name = std::string_view(reinterpret_cast<const char*>(name.data()), name.size());
  v.error = finish_block(r);
  if (v.error == WireError::None && (name_length == 0 || name_length > kMaxStationNameLength)) {
    v.error = WireError::InvalidArgument;
  }
  v.size = bb.size;
  return v;
}

std::size_t encode_ar_block_res(const ArBlockRes& b, std::span<std::uint8_t> out) noexcept {
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kArBlockRes);
  w.u16(b.ar_type);
  w.uuid(b.ar_uuid);
  w.u16(b.session_key);
  w.mac(b.responder_mac);
  w.u16(b.responder_udp_rt_port);
  end_block(w, start);
  return w.size_or_zero();
}

ArBlockResView decode_ar_block_res(std::span<const std::uint8_t> in) noexcept {
  ArBlockResView v;
  const BlockBody bb = open_block(in, block_type::kArBlockRes, kArBlockResSize - kBlockHeaderSize);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  v.block.ar_type = r.u16();
  v.block.ar_uuid = r.uuid();
  v.block.session_key = r.u16();
  v.block.responder_mac = r.mac();
  v.block.responder_udp_rt_port = r.u16();
  v.error = finish_block(r);
  v.size = bb.size;
  return v;
}

// ---- IOCR --------------------------------------------------------------------------------------

namespace {
// IOCRType .. NumberOfAPIs [IEC 61158-6-10 §5.2.2.2 IOCRBlockReq]
constexpr std::size_t kIocrReqFixed = 2 + 2 + 2 + 4 + 2 + 2 + 2 + 2 + 2 + 2 + 4 + 2 + 2 + 2 + 6 + 2;

void put_refs(Writer& w, std::span<const IoObjectRef> refs) noexcept {
  if (refs.size() > 0xFFFF) {
    w.fail(WireError::InvalidArgument);
    return;
  }
  w.u16(static_cast<std::uint16_t>(refs.size()));
  for (const IoObjectRef& o : refs) {
    w.u16(o.slot);
    w.u16(o.subslot);
    w.u16(o.frame_offset);
  }
}
}  // namespace

std::size_t encode_iocr_block_req(const IocrParams& p, std::span<const IocrApiSpec> apis,
                                  std::span<std::uint8_t> out) noexcept {
  if (apis.size() > 0xFFFF) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kIocrBlockReq);
  w.u16(p.type);
  w.u16(p.reference);
  w.u16(p.lt);
  w.u32(p.properties);
  w.u16(p.data_length);
  w.u16(p.frame_id);
  w.u16(p.send_clock_factor);
  w.u16(p.reduction_ratio);
  w.u16(p.phase);
  w.u16(p.sequence);
  w.u32(p.frame_send_offset);
  w.u16(p.watchdog_factor);
  w.u16(p.data_hold_factor);
  w.u16(p.tag_header);
  w.mac(p.multicast_mac);
  w.u16(static_cast<std::uint16_t>(apis.size()));
  for (const IocrApiSpec& a : apis) {
    w.u32(a.api);
    put_refs(w, a.data_objects);
    put_refs(w, a.iocs);
  }
  end_block(w, start);
  return w.size_or_zero();
}

IocrBlockReqView decode_iocr_block_req(std::span<const std::uint8_t> in) noexcept {
  IocrBlockReqView v;
  const BlockBody bb = open_block(in, block_type::kIocrBlockReq, kIocrReqFixed);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  IocrParams& p = v.params;
  p.type = r.u16();
  p.reference = r.u16();
  p.lt = r.u16();
  p.properties = r.u32();
  p.data_length = r.u16();
  p.frame_id = r.u16();
  p.send_clock_factor = r.u16();
  p.reduction_ratio = r.u16();
  p.phase = r.u16();
  p.sequence = r.u16();
  p.frame_send_offset = r.u32();
  p.watchdog_factor = r.u16();
  p.data_hold_factor = r.u16();
  p.tag_header = r.u16();
  p.multicast_mac = r.mac();
  v.api_count = r.u16();
  const std::size_t apis_start = r.position();
  // Validate the whole list now so IocrEntryReader walks known-good bytes.
  for (std::uint16_t a = 0; a < v.api_count && r.ok(); ++a) {
    r.skip(4);
    const std::uint16_t objects = r.u16();
    r.skip(std::size_t{objects} * 6);
    const std::uint16_t iocs = r.u16();
    r.skip(std::size_t{iocs} * 6);
  }
  v.error = finish_block(r);
  if (v.error == WireError::None) v.apis = bb.body.subspan(apis_start);
  v.size = bb.size;
  return v;
}

bool IocrEntryReader::next(IocrEntry& out) noexcept {
  for (;;) {
    if (!r_.ok()) return false;
    if (in_api_) {
      if (!in_iocs_ && objects_left_ > 0) {
        --objects_left_;
        out.api = api_;
        out.iocs = false;
        out.ref.slot = r_.u16();
        out.ref.subslot = r_.u16();
        out.ref.frame_offset = r_.u16();
        return r_.ok();
      }
      if (!in_iocs_) {
        iocs_left_ = r_.u16();
        in_iocs_ = true;
        continue;
      }
      if (iocs_left_ > 0) {
        --iocs_left_;
        out.api = api_;
        out.iocs = true;
        out.ref.slot = r_.u16();
        out.ref.subslot = r_.u16();
        out.ref.frame_offset = r_.u16();
        return r_.ok();
      }
      in_api_ = false;
    }
    if (apis_left_ == 0) return false;
    --apis_left_;
    api_ = r_.u32();
    objects_left_ = r_.u16();
    in_api_ = true;
    in_iocs_ = false;
  }
}

std::size_t encode_iocr_block_res(const IocrBlockRes& b, std::span<std::uint8_t> out) noexcept {
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kIocrBlockRes);
  w.u16(b.type);
  w.u16(b.reference);
  w.u16(b.frame_id);
  end_block(w, start);
  return w.size_or_zero();
}

IocrBlockResView decode_iocr_block_res(std::span<const std::uint8_t> in) noexcept {
  IocrBlockResView v;
  const BlockBody bb = open_block(in, block_type::kIocrBlockRes, kIocrBlockResSize - kBlockHeaderSize);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  v.block.type = r.u16();
  v.block.reference = r.u16();
  v.block.frame_id = r.u16();
  v.error = finish_block(r);
  v.size = bb.size;
  return v;
}

// ---- AlarmCR -----------------------------------------------------------------------------------

std::size_t encode_alarm_cr_block_req(const AlarmCrBlockReq& b, std::span<std::uint8_t> out) noexcept {
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kAlarmCrBlockReq);
  w.u16(b.type);
  w.u16(b.lt);
  w.u32(b.properties);
  w.u16(b.rta_timeout_factor);
  w.u16(b.rta_retries);
  w.u16(b.local_alarm_reference);
  w.u16(b.max_alarm_data_length);
  w.u16(b.tag_header_high);
  w.u16(b.tag_header_low);
  end_block(w, start);
  return w.size_or_zero();
}

AlarmCrBlockReqView decode_alarm_cr_block_req(std::span<const std::uint8_t> in) noexcept {
  AlarmCrBlockReqView v;
  const BlockBody bb = open_block(in, block_type::kAlarmCrBlockReq, kAlarmCrBlockReqSize - kBlockHeaderSize);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  AlarmCrBlockReq& b = v.block;
  b.type = r.u16();
  b.lt = r.u16();
  b.properties = r.u32();
  b.rta_timeout_factor = r.u16();
  b.rta_retries = r.u16();
  b.local_alarm_reference = r.u16();
  b.max_alarm_data_length = r.u16();
  b.tag_header_high = r.u16();
  b.tag_header_low = r.u16();
  v.error = finish_block(r);
  v.size = bb.size;
  return v;
}

std::size_t encode_alarm_cr_block_res(const AlarmCrBlockRes& b, std::span<std::uint8_t> out) noexcept {
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kAlarmCrBlockRes);
  w.u16(b.type);
  w.u16(b.local_alarm_reference);
  w.u16(b.max_alarm_data_length);
  end_block(w, start);
  return w.size_or_zero();
}

AlarmCrBlockResView decode_alarm_cr_block_res(std::span<const std::uint8_t> in) noexcept {
  AlarmCrBlockResView v;
  const BlockBody bb = open_block(in, block_type::kAlarmCrBlockRes, kAlarmCrBlockResSize - kBlockHeaderSize);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  v.block.type = r.u16();
  v.block.local_alarm_reference = r.u16();
  v.block.max_alarm_data_length = r.u16();
  v.error = finish_block(r);
  v.size = bb.size;
  return v;
}

}  // namespace drivegate::profinet
