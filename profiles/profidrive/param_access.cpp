#include "profiles/profidrive/param_access.hpp"

namespace drivegate::profidrive {

namespace {

void put_be16(std::span<std::uint8_t> b, std::size_t at, std::uint16_t v) noexcept {
  b[at] = static_cast<std::uint8_t>(v >> 8);
  b[at + 1] = static_cast<std::uint8_t>(v & 0xFFU);
}
std::uint16_t get_be16(std::span<const std::uint8_t> b, std::size_t at) noexcept {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}

bool valid_attribute(std::uint8_t a) noexcept {
  return a == static_cast<std::uint8_t>(Attribute::Value) || a == static_cast<std::uint8_t>(Attribute::Description) ||
         a == static_cast<std::uint8_t>(Attribute::Text);
}

ParamError check_address(const ParamAddress& a) noexcept {
  if (!valid_attribute(static_cast<std::uint8_t>(a.attribute))) return ParamError::BadAttribute;
  if (a.elements == 0 || a.elements > kMaxElements) return ParamError::BadElements;
  if (a.pnu == 0) return ParamError::BadPnu;
  if (a.subindex > kMaxSubindex) return ParamError::BadSubindex;
  return ParamError::None;
}

void put_address(std::span<std::uint8_t> out, std::size_t at, const ParamAddress& a) noexcept {
  out[at] = static_cast<std::uint8_t>(a.attribute);
  out[at + 1] = a.elements;
  put_be16(out, at + 2, a.pnu);
  put_be16(out, at + 4, a.subindex);
}

// Value bytes of a block, and the block with its pad to a word boundary [STD; §5.6 pads a single
// Byte value too].
constexpr std::size_t padded(std::size_t n) noexcept { return n + (n & 1U); }

struct BlockParse {
  ParamError error = ParamError::None;
  std::size_t next = 0;
  ValueBlock block;
};

// One value block at `at`; `change_response` admits the AKD's 00h format.
BlockParse parse_block(std::span<const std::uint8_t> in, std::size_t at, bool change_response, bool last) noexcept {
  BlockParse p;
  p.next = at;
  if (in.size() - at < 2) {
    p.error = ParamError::Truncated;
    return p;
  }
  p.block.format = in[at];
  p.block.count = in[at + 1];
  const std::uint8_t f = p.block.format;
  if (f == format::kAkdNone || f == format::kZero) {
    if (p.block.count != 0 || (f == format::kAkdNone && !change_response)) p.error = ParamError::BadZeroBlock;
    p.next = at + 2;
    return p;
  }
  const std::size_t size = format_size(f);
  if (size == 0) {
    p.error = ParamError::UnknownFormat;
    return p;
  }
  if (f == format::kError && p.block.count != 1 && p.block.count != 2) {
    p.error = ParamError::BadErrorBlock;
    return p;
  }
  const std::size_t n = size * p.block.count;
  if (in.size() - at - 2 < n) {
    p.error = ParamError::CountBeyondData;
    return p;
  }
  p.block.data = in.subspan(at + 2, n);
  p.next = at + 2 + n;
  // The pad after an odd block: always before another block, optional after the last one.
  if ((n & 1U) != 0 && p.next < in.size()) ++p.next;
  else if ((n & 1U) != 0 && !last) p.error = ParamError::Truncated;
  return p;
}

}  // namespace

std::size_t format_size(std::uint8_t fmt) noexcept {
  switch (fmt) {
    case format::kInteger8:
    case format::kUnsigned8:
    case format::kVisibleString:
    case format::kOctetString:
    case format::kByte: return 1;
    case format::kInteger16:
    case format::kUnsigned16:
    case format::kWord:
    case format::kError: return 2;
    case format::kInteger32:
    case format::kUnsigned32:
    case format::kFloat32:
    case format::kDWord: return 4;
    default: return 0;
  }
}

bool is_value_format(std::uint8_t fmt) noexcept { return fmt != format::kError && format_size(fmt) != 0; }

std::string_view to_string(ParamError e) noexcept {
  switch (e) {
    case ParamError::None: return "ok";
    case ParamError::BufferTooSmall: return "buffer too small for the request";
    case ParamError::BadReference: return "request reference 0 is reserved";
    case ParamError::BadCount: return "number of parameters not 1..39";
    case ParamError::BadElements: return "number of elements not 1..234";
    case ParamError::BadPnu: return "parameter number 0";
    case ParamError::BadSubindex: return "subindex FFFFh";
    case ParamError::BadFormat: return "change format not 41h/42h/43h";
    case ParamError::ValueCountMismatch: return "number of values differs from the number of elements";
    case ParamError::ValueTooWide: return "value does not fit its format";
    case ParamError::TooLong: return "request longer than 240 bytes";
    case ParamError::Truncated: return "truncated";
    case ParamError::UnknownId: return "unknown request/response ID";
    case ParamError::BadAttribute: return "unknown attribute";
    case ParamError::UnknownFormat: return "unknown value format";
    case ParamError::CountBeyondData: return "number of values runs past the end of the record";
    case ParamError::BadErrorBlock: return "error block without 1 or 2 values";
    case ParamError::BadZeroBlock: return "empty block with values, or format 00h outside a change response";
    case ParamError::TrailingBytes: return "bytes after the last block";
    case ParamError::ErrorInPositive: return "error block in a positive response";
    case ParamError::NoErrorInNegative: return "negative response without an error block";
  }
  return "unknown parameter-access error";
}

EncodeResult encode_read_request(std::span<std::uint8_t> out, std::uint8_t reference,
                                 std::span<const ParamAddress> params, std::uint8_t axis) noexcept {
  EncodeResult r;
  if (reference == 0) return {ParamError::BadReference, 0, 0};
  if (params.empty() || params.size() > kMaxParameters) return {ParamError::BadCount, 0, 0};
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (const ParamError e = check_address(params[i]); e != ParamError::None) return {e, 0, i};
  }
  const std::size_t size = kParamHeaderSize + kParamAddressSize * params.size();
  if (out.size() < size) return {ParamError::BufferTooSmall, 0, 0};
  out[0] = reference;
  out[1] = static_cast<std::uint8_t>(RequestId::Read);
  out[2] = axis;
  out[3] = static_cast<std::uint8_t>(params.size());
  for (std::size_t i = 0; i < params.size(); ++i) put_address(out, kParamHeaderSize + kParamAddressSize * i, params[i]);
  r.size = size;
  return r;
}

EncodeResult encode_change_request(std::span<std::uint8_t> out, std::uint8_t reference,
                                   std::span<const ParamChange> params, std::uint8_t axis) noexcept {
  if (reference == 0) return {ParamError::BadReference, 0, 0};
  if (params.empty() || params.size() > kMaxParameters) return {ParamError::BadCount, 0, 0};
  std::size_t size = kParamHeaderSize + kParamAddressSize * params.size();
  for (std::size_t i = 0; i < params.size(); ++i) {
    const ParamChange& p = params[i];
    if (const ParamError e = check_address(p.address); e != ParamError::None) return {e, 0, i};
    if (p.format != format::kByte && p.format != format::kWord && p.format != format::kDWord)
      return {ParamError::BadFormat, 0, i};
    if (p.values.size() != p.address.elements) return {ParamError::ValueCountMismatch, 0, i};
    const std::size_t w = format_size(p.format);
    const std::uint32_t max = w == 1 ? 0xFFU : w == 2 ? 0xFFFFU : 0xFFFFFFFFU;
    for (const std::uint32_t v : p.values) {
      if (v > max) return {ParamError::ValueTooWide, 0, i};
    }
    size += 2 + padded(w * p.values.size());
  }
  if (size > kMaxParamRecord) return {ParamError::TooLong, 0, 0};
  if (out.size() < size) return {ParamError::BufferTooSmall, 0, 0};
  out[0] = reference;
  out[1] = static_cast<std::uint8_t>(RequestId::Change);
  out[2] = axis;
  out[3] = static_cast<std::uint8_t>(params.size());
  std::size_t at = kParamHeaderSize;
  for (const ParamChange& p : params) {
    put_address(out, at, p.address);
    at += kParamAddressSize;
  }
  for (const ParamChange& p : params) {
    const std::size_t w = format_size(p.format);
    out[at++] = p.format;
    out[at++] = static_cast<std::uint8_t>(p.values.size());
    for (const std::uint32_t v : p.values) {
      for (std::size_t k = w; k-- > 0;) out[at++] = static_cast<std::uint8_t>((v >> (8 * k)) & 0xFFU);
    }
    if (((w * p.values.size()) & 1U) != 0) out[at++] = 0;
  }
  return {ParamError::None, at, 0};
}

EncodeResult encode_param_response(std::span<std::uint8_t> out, const ParamResponse& response) noexcept {
  const std::uint8_t id = response.response_id;
  if (id != response_id::kReadOk && id != response_id::kChangeOk && id != response_id::kReadFailed &&
      id != response_id::kChangeFailed)
    return {ParamError::UnknownId, 0, 0};
  if (response.count == 0 || response.count > kMaxParameters) return {ParamError::BadCount, 0, 0};
  if (response.block_count != response.count && !(response.block_count == 0 && id == response_id::kChangeOk))
    return {ParamError::BadCount, 0, 0};
  std::size_t size = kParamHeaderSize;
  for (std::size_t i = 0; i < response.block_count; ++i) {
    const ValueBlock& b = response.blocks[i];
    if (b.format == format::kAkdNone || b.format == format::kZero) {
      if (b.count != 0 || !b.data.empty()) return {ParamError::BadZeroBlock, 0, i};
    } else if (format_size(b.format) == 0) {
      return {ParamError::UnknownFormat, 0, i};
    } else if (b.data.size() != format_size(b.format) * b.count) {
      return {ParamError::CountBeyondData, 0, i};
    }
    size += 2 + padded(b.data.size());
  }
  if (size > kMaxParamRecord) return {ParamError::TooLong, 0, 0};
  if (out.size() < size) return {ParamError::BufferTooSmall, 0, 0};
  out[0] = response.reference;
  out[1] = id;
  out[2] = response.axis;
  out[3] = response.count;
  std::size_t at = kParamHeaderSize;
  for (std::size_t i = 0; i < response.block_count; ++i) {
    const ValueBlock& b = response.blocks[i];
    out[at++] = b.format;
    out[at++] = b.count;
    for (const std::uint8_t byte : b.data) out[at++] = byte;
    if ((b.data.size() & 1U) != 0) out[at++] = 0;
  }
  return {ParamError::None, at, 0};
}

std::uint32_t ValueBlock::value(std::size_t i) const noexcept {
  const std::size_t w = format_size(format);
  if (w == 0 || (i + 1) * w > data.size()) return 0;
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < w; ++k) v = (v << 8) | data[i * w + k];
  return v;
}

std::optional<std::uint16_t> ValueBlock::error_info() const noexcept {
  if (!is_error() || count < 2) return std::nullopt;
  return static_cast<std::uint16_t>(value(1));
}

ResponseResult decode_param_response(std::span<const std::uint8_t> in) noexcept {
  ResponseResult r;
  if (in.size() < kParamHeaderSize) {
    r.error = ParamError::Truncated;
    return r;
  }
  ParamResponse& p = r.response;
  p.reference = in[0];
  p.response_id = in[1];
  p.axis = in[2];
  p.count = in[3];
  r.at = kParamHeaderSize;
  if (p.response_id != response_id::kReadOk && p.response_id != response_id::kChangeOk &&
      p.response_id != response_id::kReadFailed && p.response_id != response_id::kChangeFailed) {
    r.error = ParamError::UnknownId;
    r.at = 1;
    return r;
  }
  if (p.count == 0 || p.count > kMaxParameters) {
    r.error = ParamError::BadCount;
    r.at = 3;
    return r;
  }
  // A positive change response may be the header alone [STD, §5.3].
  if (p.response_id == response_id::kChangeOk && in.size() == kParamHeaderSize) return r;
  bool any_error = false;
  std::size_t at = kParamHeaderSize;
  for (std::size_t i = 0; i < p.count; ++i) {
    const BlockParse b = parse_block(in, at, p.is_change(), i + 1 == p.count);
    if (b.error != ParamError::None) {
      r.error = b.error;
      r.at = at;
      p.block_count = static_cast<std::uint8_t>(i);
      return r;
    }
    p.blocks[i] = b.block;
    any_error = any_error || b.block.is_error();
    at = b.next;
  }
  p.block_count = p.count;
  r.at = at;
  if (at != in.size()) r.error = ParamError::TrailingBytes;
  else if (p.positive() && any_error) r.error = ParamError::ErrorInPositive;
  else if (!p.positive() && !any_error) r.error = ParamError::NoErrorInNegative;
  return r;
}

RequestResult decode_param_request(std::span<const std::uint8_t> in) noexcept {
  RequestResult r;
  if (in.size() < kParamHeaderSize) {
    r.error = ParamError::Truncated;
    return r;
  }
  ParamRequest& q = r.request;
  q.reference = in[0];
  q.axis = in[2];
  q.count = in[3];
  if (in[1] != static_cast<std::uint8_t>(RequestId::Read) && in[1] != static_cast<std::uint8_t>(RequestId::Change)) {
    r.error = ParamError::UnknownId;
    r.at = 1;
    return r;
  }
  q.id = static_cast<RequestId>(in[1]);
  if (q.reference == 0) {
    r.error = ParamError::BadReference;
    return r;
  }
  if (q.count == 0 || q.count > kMaxParameters) {
    r.error = ParamError::BadCount;
    r.at = 3;
    return r;
  }
  std::size_t at = kParamHeaderSize;
  for (std::size_t i = 0; i < q.count; ++i, at += kParamAddressSize) {
    if (in.size() - at < kParamAddressSize) {
      r.error = ParamError::Truncated;
      r.at = at;
      q.count = static_cast<std::uint8_t>(i);
      return r;
    }
    ParamAddress& a = q.params[i];
    a.attribute = static_cast<Attribute>(in[at]);
    a.elements = in[at + 1];
    a.pnu = get_be16(in, at + 2);
    a.subindex = get_be16(in, at + 4);
    if (const ParamError e = check_address(a); e != ParamError::None) {
      r.error = e;
      r.at = at;
      return r;
    }
  }
  if (q.id == RequestId::Change) {
    for (std::size_t i = 0; i < q.count; ++i) {
      const BlockParse b = parse_block(in, at, false, i + 1 == q.count);
      if (b.error != ParamError::None || !is_value_format(b.block.format)) {
        r.error = b.error != ParamError::None ? b.error : ParamError::BadFormat;
        r.at = at;
        return r;
      }
      if (b.block.count != q.params[i].elements) {
        r.error = ParamError::ValueCountMismatch;
        r.at = at;
        return r;
      }
      q.values[i] = b.block;
      at = b.next;
    }
  }
  r.at = at;
  if (at != in.size()) r.error = ParamError::TrailingBytes;
  return r;
}

std::string_view to_string(ParamMismatch m) noexcept {
  switch (m) {
    case ParamMismatch::None: return "ok";
    case ParamMismatch::Reference: return "response reference differs from the request's";
    case ParamMismatch::ResponseId: return "response ID does not answer the request ID";
    case ParamMismatch::Axis: return "response axis differs from the request's";
    case ParamMismatch::ParameterCount: return "response has another number of parameters than the request";
    case ParamMismatch::ValueCount: return "value count differs from the number of elements requested";
    case ParamMismatch::Format: return "read answered without values";
    case ParamMismatch::ValuesInChange: return "change answered with values";
  }
  return "unknown mismatch";
}

CheckResult check_response(const ParamRequest& request, const ParamResponse& response) noexcept {
  if (response.reference != request.reference) return {ParamMismatch::Reference, 0};
  const bool change = request.id == RequestId::Change;
  if (response.is_change() != change || (response.response_id & 0x7CU) != 0) return {ParamMismatch::ResponseId, 0};
  if (response.axis != request.axis) return {ParamMismatch::Axis, 0};
  if (response.count != request.count) return {ParamMismatch::ParameterCount, 0};
  for (std::size_t i = 0; i < response.block_count && i < request.count; ++i) {
    const ValueBlock& b = response.blocks[i];
    if (b.is_error()) continue;
    if (change) {
      if (!b.is_empty()) return {ParamMismatch::ValuesInChange, i};
      continue;
    }
    if (b.is_empty()) return {ParamMismatch::Format, i};
    // A value read returns one value per element; descriptions and texts have their own shape.
    if (request.params[i].attribute == Attribute::Value && b.count != request.params[i].elements)
      return {ParamMismatch::ValueCount, i};
  }
  return {};
}

std::string_view param_error_text(std::uint16_t error_number) noexcept {
  switch (error_number) {
    case 0x00: return "impermissible parameter number (the parameter does not exist)";
    case 0x01: return "parameter value cannot be changed (read-only)";
    case 0x02: return "low or high limit exceeded";
    case 0x03: return "faulty subindex";
    case 0x04: return "no array (the parameter has no subindices)";
    case 0x05: return "incorrect data type";
    case 0x06: return "setting not permitted (may only be reset)";
    case 0x07: return "description element cannot be changed";
    case 0x09: return "description data not available";
    case 0x0B: return "no master control (no parameter change rights)";
    case 0x0F: return "text array not available";
    case 0x11: return "request cannot be executed in the current operating state";
    case 0x14: return "value impermissible";
    case 0x15: return "response too long";
    case 0x16: return "parameter address impermissible (attribute, elements, PNU or subindex)";
    case 0x17: return "illegal format";
    case 0x18: return "number of values inconsistent";
    case 0x19: return "drive object (axis) does not exist";
    default: break;
  }
  if (error_number >= 0x65 && error_number <= 0xFF) return "manufacturer-specific error (not documented for the AKD)";
  return "reserved error number";
}

}  // namespace drivegate::profidrive
