#include "adapters/profinet/wire/blocks_record.hpp"

#include <array>

namespace drivegate::profinet {

namespace {

constexpr std::size_t kRecordBody = kRecordHeaderSize - kBlockHeaderSize;  // 58

void put_address(Writer& w, std::uint16_t seq, const Uuid& ar, std::uint32_t api, std::uint16_t slot,
                 std::uint16_t subslot, std::uint16_t index, std::uint32_t length) noexcept {
  w.u16(seq);
  w.uuid(ar);
  w.u32(api);
  w.u16(slot);
  w.u16(subslot);
  w.zeros(2);  // padding
  w.u16(index);
  w.u32(length);
}

std::string_view trimmed(std::span<const std::uint8_t> b) noexcept {
  std::size_t n = b.size();
  while (n > 0 && (b[n - 1] == ' ' || b[n - 1] == 0)) --n;
  return {reinterpret_cast<const char*>(b.data()), n};
}

void put_padded(Writer& w, std::string_view s, std::size_t width) noexcept {
  w.text(s);
  for (std::size_t i = s.size(); i < width; ++i) w.u8(' ');
}

}  // namespace

std::size_t encode_record_req_header(const RecordReqHeader& h, std::span<std::uint8_t> out) noexcept {
  if (h.type != block_type::kWriteReqHeader && h.type != block_type::kReadReqHeader) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, h.type);
  put_address(w, h.sequence_number, h.ar_uuid, h.api, h.slot, h.subslot, h.index, h.record_data_length);
  if (h.type == block_type::kReadReqHeader) {
    w.uuid(h.target_ar_uuid);  // nil for an explicit read
    w.zeros(8);
  } else {
    w.zeros(24);
  }
  end_block(w, start);
  return w.size_or_zero();
}

std::size_t encode_record_res_header(const RecordResHeader& h, std::span<std::uint8_t> out) noexcept {
  if (h.type != block_type::kWriteResHeader && h.type != block_type::kReadResHeader) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, h.type);
  put_address(w, h.sequence_number, h.ar_uuid, h.api, h.slot, h.subslot, h.index, h.record_data_length);
  w.u16(h.additional_value1);
  w.u16(h.additional_value2);
  if (h.type == block_type::kWriteResHeader) {
    w.u8(h.status.code);
    w.u8(h.status.decode);
    w.u8(h.status.code1);
    w.u8(h.status.code2);
    w.zeros(16);
  } else {
    w.zeros(20);
  }
  end_block(w, start);
  return w.size_or_zero();
}

RecordResHeader record_response_for(const RecordReqHeader& request, std::uint32_t length,
                                    const PnioStatus& status) noexcept {
  RecordResHeader h;
  h.type = static_cast<std::uint16_t>(request.type | 0x8000);
  h.sequence_number = request.sequence_number;
  h.ar_uuid = request.ar_uuid;
  h.api = request.api;
  h.slot = request.slot;
  h.subslot = request.subslot;
  h.index = request.index;
  h.record_data_length = length;
  h.status = status;
  return h;
}

RecordReqView decode_record_request(std::span<const std::uint8_t> in) noexcept {
  RecordReqView v;
  static constexpr std::array<std::uint16_t, 2> kTypes{block_type::kWriteReqHeader, block_type::kReadReqHeader};
  const BlockBody bb = open_block_of(in, kTypes, kRecordBody);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  RecordReqHeader& h = v.header;
  h.type = bb.header.type;
  h.sequence_number = r.u16();
  h.ar_uuid = r.uuid();
  h.api = r.u32();
  h.slot = r.u16();
  h.subslot = r.u16();
  r.skip(2);
  h.index = r.u16();
  h.record_data_length = r.u32();
  if (h.type == block_type::kReadReqHeader) {
    h.target_ar_uuid = r.uuid();
    r.skip(8);
  } else {
    r.skip(24);
  }
  v.error = finish_block(r);
  v.size = bb.size;
  if (v.error != WireError::None || h.type != block_type::kWriteReqHeader) return v;
  // The data follows the header; RecordDataLength must not promise more than the args hold.
  if (h.record_data_length > in.size() - bb.size) {
    v.error = WireError::CountBeyondData;
    return v;
  }
  v.data = in.subspan(bb.size, h.record_data_length);
  v.size += v.data.size();
  return v;
}

RecordResView decode_record_response(std::span<const std::uint8_t> in) noexcept {
  RecordResView v;
  static constexpr std::array<std::uint16_t, 2> kTypes{block_type::kWriteResHeader, block_type::kReadResHeader};
  const BlockBody bb = open_block_of(in, kTypes, kRecordBody);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  RecordResHeader& h = v.header;
  h.type = bb.header.type;
  h.sequence_number = r.u16();
  h.ar_uuid = r.uuid();
  h.api = r.u32();
  h.slot = r.u16();
  h.subslot = r.u16();
  r.skip(2);
  h.index = r.u16();
  h.record_data_length = r.u32();
  h.additional_value1 = r.u16();
  h.additional_value2 = r.u16();
  if (h.type == block_type::kWriteResHeader) {
    h.status.code = r.u8();
    h.status.decode = r.u8();
    h.status.code1 = r.u8();
    h.status.code2 = r.u8();
    r.skip(16);
  } else {
    r.skip(20);
  }
  v.error = finish_block(r);
  v.size = bb.size;
  if (v.error != WireError::None || h.type != block_type::kReadResHeader) return v;
  if (h.record_data_length > in.size() - bb.size) {
    v.error = WireError::CountBeyondData;
    return v;
  }
  v.data = in.subspan(bb.size, h.record_data_length);
  v.size += v.data.size();
  return v;
}

// ---- I&M0 --------------------------------------------------------------------------------------

std::size_t encode_im0(const Im0& m, std::span<std::uint8_t> out) noexcept {
  if (m.order_id.size() > 20 || m.serial_number.size() > 16) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kIm0);
  w.u16(m.vendor_id);
  put_padded(w, m.order_id, 20);
  put_padded(w, m.serial_number, 16);
  w.u16(m.hardware_revision);
  w.u8(static_cast<std::uint8_t>(m.software_prefix));
  w.u8(m.software_functional);
  w.u8(m.software_bugfix);
  w.u8(m.software_internal);
  w.u16(m.revision_counter);
  w.u16(m.profile_id);
  w.u16(m.profile_specific_type);
  w.u8(m.im_version_major);
  w.u8(m.im_version_minor);
  w.u16(m.im_supported);
  end_block(w, start);
  return w.size_or_zero();
}

Im0View decode_im0(std::span<const std::uint8_t> in) noexcept {
  Im0View v;
  const BlockBody bb = open_block(in, block_type::kIm0, kIm0Size - kBlockHeaderSize);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  Im0& m = v.im0;
  m.vendor_id = r.u16();
  m.order_id = trimmed(r.bytes(20));
  m.serial_number = trimmed(r.bytes(16));
  m.hardware_revision = r.u16();
  m.software_prefix = static_cast<char>(r.u8());
  m.software_functional = r.u8();
  m.software_bugfix = r.u8();
  m.software_internal = r.u8();
  m.revision_counter = r.u16();
  m.profile_id = r.u16();
  m.profile_specific_type = r.u16();
  m.im_version_major = r.u8();
  m.im_version_minor = r.u8();
  m.im_supported = r.u16();
  v.error = finish_block(r);
  v.size = bb.size;
  return v;
}

std::size_t encode_im1(const Im1& m, std::span<std::uint8_t> out) noexcept {
  if (m.tag_function.size() > 32 || m.tag_location.size() > 22) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, block_type::kIm1);
  put_padded(w, m.tag_function, 32);
  put_padded(w, m.tag_location, 22);
  end_block(w, start);
  return w.size_or_zero();
}

Im1View decode_im1(std::span<const std::uint8_t> in) noexcept {
  Im1View v;
  const BlockBody bb = open_block(in, block_type::kIm1, kIm1Size - kBlockHeaderSize);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  v.im1.tag_function = trimmed(r.bytes(32));
  v.im1.tag_location = trimmed(r.bytes(22));
  v.error = finish_block(r);
  if (v.error == WireError::None && bb.size != in.size()) v.error = WireError::BlockLengthMismatch;  // bytes after the block
  return v;
}

}  // namespace drivegate::profinet
