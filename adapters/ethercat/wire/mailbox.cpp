#include "adapters/ethercat/wire/mailbox.hpp"

#include <algorithm>

#include "core/bytes.hpp"

namespace drivegate::ethercat {

using core::get_u16;
using core::get_u32;
using core::put_u16;
using core::put_u32;

std::string_view to_string(MailboxType t) noexcept {
  switch (t) {
    case MailboxType::Error: return "ERR";
    case MailboxType::AoE: return "AoE";
    case MailboxType::EoE: return "EoE";
    case MailboxType::CoE: return "CoE";
    case MailboxType::FoE: return "FoE";
    case MailboxType::SoE: return "SoE";
    case MailboxType::VoE: return "VoE";
  }
  return "unknown";
}

std::string_view to_string(MailboxError e) noexcept {
  switch (e) {
    case MailboxError::None: return "no error";
    case MailboxError::TruncatedHeader: return "mailbox shorter than its 6-byte header";
    case MailboxError::LengthBeyondBuffer: return "mailbox length runs past the bytes read";
    case MailboxError::WrongType: return "unexpected mailbox type";
    case MailboxError::TruncatedCoeHeader: return "mailbox too short for the CoE header";
    case MailboxError::UnexpectedService: return "unexpected CoE service";
    case MailboxError::TruncatedSdo: return "CoE SDO shorter than 8 bytes";
    case MailboxError::UnknownSdoCommand: return "unknown SDO command specifier";
    case MailboxError::SizeMismatch: return "SDO data longer than the complete size it indicates";
    case MailboxError::TruncatedEmergency: return "CoE emergency shorter than 8 bytes";
    case MailboxError::TruncatedSdoInfo: return "SDO information message cut off";
    case MailboxError::UnknownSdoInfoOpcode: return "unknown SDO information opcode";
    case MailboxError::TruncatedMailboxError: return "mailbox error reply shorter than 4 bytes";
  }
  return "?";
}

bool encode_mailbox_header(const MailboxHeader& h, std::span<std::uint8_t> out) noexcept {
  if (out.size() < kMailboxHeaderSize || h.channel > 63 || h.priority > 3 || h.type > 15 || h.counter > 7) return false;
  put_u16(out, 0, h.length);
  put_u16(out, 2, h.address);
  out[4] = static_cast<std::uint8_t>(h.channel | (h.priority << 6));
  out[5] = static_cast<std::uint8_t>(h.type | (h.counter << 4));
  return true;
}

MailboxView decode_mailbox(std::span<const std::uint8_t> in) noexcept {
  MailboxView v;
  if (in.size() < kMailboxHeaderSize) {
    v.error = MailboxError::TruncatedHeader;
    return v;
  }
  v.header.length = get_u16(in, 0);
  v.header.address = get_u16(in, 2);
  v.header.channel = static_cast<std::uint8_t>(in[4] & 0x3F);
  v.header.priority = static_cast<std::uint8_t>(in[4] >> 6);
  v.header.type = static_cast<std::uint8_t>(in[5] & 0x0F);
  v.header.counter = static_cast<std::uint8_t>((in[5] >> 4) & 0x07);
  if (v.header.length > in.size() - kMailboxHeaderSize) {
    v.error = MailboxError::LengthBeyondBuffer;
    return v;
  }
  v.payload = in.subspan(kMailboxHeaderSize, v.header.length);
  return v;
}

// ---- Mailbox error reply ----------------------------------------------------------------------

std::string_view mailbox_error_text(std::uint16_t detail) noexcept {
  // [ETG.1000.6 mailbox error reply, detail codes]
  switch (detail) {
    case mailbox_error_code::kSyntax: return "syntax of the 6-byte mailbox header is wrong";
    case mailbox_error_code::kUnsupportedProtocol: return "mailbox protocol not supported";
    case mailbox_error_code::kInvalidChannel: return "channel field holds a wrong value";
    case mailbox_error_code::kServiceNotSupported: return "service in the mailbox protocol not supported";
    case mailbox_error_code::kInvalidHeader: return "protocol header of the mailbox protocol is wrong";
    case mailbox_error_code::kSizeTooShort: return "received mailbox data too short";
    case mailbox_error_code::kNoMoreMemory: return "mailbox protocol cannot be processed: no resources";
    case mailbox_error_code::kInvalidSize: return "length of the data is inconsistent";
    case mailbox_error_code::kServiceInWork: return "mailbox service already in use";
    default: return "unknown mailbox error";
  }
}

MailboxErrorReply decode_mailbox_error(std::span<const std::uint8_t> in) noexcept {
  MailboxErrorReply r;
  const MailboxView v = decode_mailbox(in);
  if (v.error != MailboxError::None) {
    r.error = v.error;
    return r;
  }
  if (v.header.type != static_cast<std::uint8_t>(MailboxType::Error)) {
    r.error = MailboxError::WrongType;
    return r;
  }
  if (v.payload.size() < 4) {
    r.error = MailboxError::TruncatedMailboxError;
    return r;
  }
  r.type = get_u16(v.payload, 0);
  r.detail = get_u16(v.payload, 2);
  return r;
}

namespace {

// Writes a mailbox header of `type` with `length` bytes after it; false when `out` is too small.
bool put_header(std::span<std::uint8_t> out, std::uint8_t counter, MailboxType type, std::size_t length) noexcept {
  if (length > 0xFFFF || out.size() < kMailboxHeaderSize + length) return false;
  MailboxHeader h;
  h.length = static_cast<std::uint16_t>(length);
  h.type = static_cast<std::uint8_t>(type);
  h.counter = counter;
  return encode_mailbox_header(h, out);
}

// Mailbox + CoE headers; returns false when `out` cannot hold `body` bytes after them.
bool put_coe(std::span<std::uint8_t> out, std::uint8_t counter, CoeService service, std::size_t body) noexcept {
  if (!put_header(out, counter, MailboxType::CoE, kCoeHeaderSize + body)) return false;
  put_u16(out, kMailboxHeaderSize, static_cast<std::uint16_t>(static_cast<unsigned>(service) << 12));
  return true;
}

constexpr std::size_t kSdoAt = kMailboxHeaderSize + kCoeHeaderSize;  // offset of the SDO command byte

// Initiate-type SDO (command, index, subindex, 4 bytes) plus `extra` data bytes.
std::size_t put_sdo(std::span<std::uint8_t> out, std::uint8_t counter, CoeService service, std::uint8_t command,
                    std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> four,
                    std::span<const std::uint8_t> extra) noexcept {
  const std::size_t body = kSdoHeaderSize + extra.size();
  if (four.size() > 4 || !put_coe(out, counter, service, body)) return 0;
  out[kSdoAt] = command;
  put_u16(out, kSdoAt + 1, index);
  out[kSdoAt + 3] = subindex;
  std::fill(out.begin() + kSdoAt + 4, out.begin() + kSdoAt + 8, std::uint8_t{0});
  std::copy(four.begin(), four.end(), out.begin() + kSdoAt + 4);
  std::copy(extra.begin(), extra.end(), out.begin() + static_cast<std::ptrdiff_t>(kSdoAt + kSdoHeaderSize));
  return kMailboxHeaderSize + kCoeHeaderSize + body;
}

// Segment-type SDO: command byte then the data, padded to 7 bytes when shorter; the unused count
// goes to bits 1-3 [ETG.1000.6 §5.6.2.3 "Seg Data Size"].
std::size_t put_segment(std::span<std::uint8_t> out, std::uint8_t counter, CoeService service, std::uint8_t command,
                        std::span<const std::uint8_t> data) noexcept {
  const std::size_t n = std::max(data.size(), kSdoSegmentMinData);
  if (!put_coe(out, counter, service, 1 + n)) return 0;
  if (data.size() < kSdoSegmentMinData) {
    command = static_cast<std::uint8_t>(command | ((kSdoSegmentMinData - data.size()) << 1));
  }
  out[kSdoAt] = command;
  std::fill(out.begin() + kSdoAt + 1, out.begin() + static_cast<std::ptrdiff_t>(kSdoAt + 1 + n), std::uint8_t{0});
  std::copy(data.begin(), data.end(), out.begin() + kSdoAt + 1);
  return kSdoAt + 1 + n;
}

constexpr std::uint8_t kCa = 0x10;  // complete access (initiate) / toggle (segments): bit 4

std::uint8_t expedited_command(std::uint8_t cs, std::size_t size, bool ca) noexcept {
  // cs in bits 5-7, n = 4 - size in bits 2-3, e = 1, s = 1
  const auto unused = static_cast<unsigned>(4 - size);
  return static_cast<std::uint8_t>((static_cast<unsigned>(cs) << 5) | (unused << 2) | 0x03U | (ca ? kCa : 0U));
}

}  // namespace

std::size_t encode_mailbox_error(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t detail) noexcept {
  if (!put_header(out, counter, MailboxType::Error, 4)) return 0;
  put_u16(out, kMailboxHeaderSize, 0x0001);  // type: mailbox command
  put_u16(out, kMailboxHeaderSize + 2, detail);
  return kMailboxHeaderSize + 4;
}

// ---- CoE --------------------------------------------------------------------------------------

std::string_view to_string(CoeService s) noexcept {
  switch (s) {
    case CoeService::Emergency: return "emergency";
    case CoeService::SdoRequest: return "SDO request";
    case CoeService::SdoResponse: return "SDO response";
    case CoeService::TxPdo: return "TxPDO";
    case CoeService::RxPdo: return "RxPDO";
    case CoeService::TxPdoRemoteRequest: return "TxPDO remote request";
    case CoeService::RxPdoRemoteRequest: return "RxPDO remote request";
    case CoeService::SdoInformation: return "SDO information";
  }
  return "unknown CoE service";
}

CoeView decode_coe(std::span<const std::uint8_t> in) noexcept {
  CoeView c;
  const MailboxView v = decode_mailbox(in);
  c.mailbox = v.header;
  if (v.error != MailboxError::None) {
    c.error = v.error;
    return c;
  }
  if (v.header.type != static_cast<std::uint8_t>(MailboxType::CoE)) {
    c.error = MailboxError::WrongType;
    return c;
  }
  if (v.payload.size() < kCoeHeaderSize) {
    c.error = MailboxError::TruncatedCoeHeader;
    return c;
  }
  const std::uint16_t h = get_u16(v.payload, 0);
  c.number = static_cast<std::uint16_t>(h & 0x01FF);
  c.service = static_cast<std::uint8_t>(h >> 12);
  c.body = v.payload.subspan(kCoeHeaderSize);
  return c;
}

std::string_view to_string(SdoCommand c) noexcept {
  switch (c) {
    case SdoCommand::DownloadInitiateRequest: return "initiate download request";
    case SdoCommand::DownloadSegmentRequest: return "download segment request";
    case SdoCommand::UploadInitiateRequest: return "initiate upload request";
    case SdoCommand::UploadSegmentRequest: return "upload segment request";
    case SdoCommand::DownloadInitiateResponse: return "initiate download response";
    case SdoCommand::DownloadSegmentResponse: return "download segment response";
    case SdoCommand::UploadInitiateResponse: return "initiate upload response";
    case SdoCommand::UploadSegmentResponse: return "upload segment response";
    case SdoCommand::Abort: return "abort transfer";
  }
  return "?";
}

namespace {

enum class Direction { Request, Response };

void decode_initiate(std::span<const std::uint8_t> b, CoeSdo& s, SdoView& v) noexcept {
  const std::uint8_t cmd = b[0];
  s.index = get_u16(b, 1);
  s.subindex = b[3];
  s.complete_access = (cmd & kCa) != 0;
  s.expedited = (cmd & 0x02) != 0;
  s.size_indicated = (cmd & 0x01) != 0;
  if (s.expedited) {
    const std::size_t n = s.size_indicated ? 4U - ((cmd >> 2) & 0x03U) : 4U;
    s.size = static_cast<std::uint32_t>(n);
    s.data = b.subspan(4, n);
  } else {
    s.size = s.size_indicated ? get_u32(b, 4) : 0;
    s.data = b.subspan(kSdoHeaderSize);
    if (s.size_indicated && s.data.size() > s.size) v.error = MailboxError::SizeMismatch;
  }
}

// Segment: data = the bytes after the command, or 7 - n of them in a minimum-size segment.
void decode_segment(std::span<const std::uint8_t> b, CoeSdo& s) noexcept {
  const std::uint8_t cmd = b[0];
  s.toggle = (cmd & 0x10) != 0;
  s.last = (cmd & 0x01) != 0;
  const auto rest = b.subspan(1);
  if (rest.size() == kSdoSegmentMinData) {
    s.data = rest.first(kSdoSegmentMinData - ((cmd >> 1) & 0x07U));
  } else {
    s.data = rest;  // longer segments carry no unused count [ETG.1000.6 §5.6.2.3]
  }
  s.size = static_cast<std::uint32_t>(s.data.size());
}

SdoView decode_sdo(std::span<const std::uint8_t> in, Direction dir) noexcept {
  SdoView v;
  const CoeView c = decode_coe(in);
  v.mailbox = c.mailbox;
  if (c.error != MailboxError::None) {
    v.error = c.error;
    return v;
  }
  const auto service = static_cast<CoeService>(c.service);
  // Requests travel as service 2, responses as 3; aborts as 2 from either side (some servers use 3).
  const bool abort_ok = service == CoeService::SdoRequest || service == CoeService::SdoResponse;
  const CoeService expected = dir == Direction::Request ? CoeService::SdoRequest : CoeService::SdoResponse;
  if (!abort_ok) {
    v.error = MailboxError::UnexpectedService;
    return v;
  }
  if (c.body.size() < kSdoHeaderSize) {
    v.error = MailboxError::TruncatedSdo;
    return v;
  }
  CoeSdo& s = v.sdo;
  const std::uint8_t cs = static_cast<std::uint8_t>(c.body[0] >> 5);
  if (cs == 4) {
    s.command = SdoCommand::Abort;
    s.index = get_u16(c.body, 1);
    s.subindex = c.body[3];
    s.abort_code = get_u32(c.body, 4);
    return v;
  }
  if (service != expected) {
    v.error = MailboxError::UnexpectedService;
    return v;
  }
  if (dir == Direction::Request) {
    switch (cs) {
      case 0: s.command = SdoCommand::DownloadSegmentRequest; decode_segment(c.body, s); break;
      case 1: s.command = SdoCommand::DownloadInitiateRequest; decode_initiate(c.body, s, v); break;
      case 2:
        s.command = SdoCommand::UploadInitiateRequest;
        s.index = get_u16(c.body, 1);
        s.subindex = c.body[3];
        s.complete_access = (c.body[0] & kCa) != 0;
        break;
      case 3:
        s.command = SdoCommand::UploadSegmentRequest;
        s.toggle = (c.body[0] & 0x10) != 0;
        break;
      default: v.error = MailboxError::UnknownSdoCommand; break;
    }
  } else {
    switch (cs) {
      case 0: s.command = SdoCommand::UploadSegmentResponse; decode_segment(c.body, s); break;
      case 1:
        s.command = SdoCommand::DownloadSegmentResponse;
        s.toggle = (c.body[0] & 0x10) != 0;
        break;
      case 2: s.command = SdoCommand::UploadInitiateResponse; decode_initiate(c.body, s, v); break;
      case 3:
        s.command = SdoCommand::DownloadInitiateResponse;
        s.index = get_u16(c.body, 1);
        s.subindex = c.body[3];
        s.complete_access = (c.body[0] & kCa) != 0;
        break;
      default: v.error = MailboxError::UnknownSdoCommand; break;
    }
  }
  return v;
}

}  // namespace

SdoView decode_sdo_request(std::span<const std::uint8_t> in) noexcept { return decode_sdo(in, Direction::Request); }
SdoView decode_sdo_response(std::span<const std::uint8_t> in) noexcept { return decode_sdo(in, Direction::Response); }

std::size_t encode_sdo_download_expedited(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                          std::uint8_t subindex, std::span<const std::uint8_t> value,
                                          bool complete_access) noexcept {
  if (value.empty() || value.size() > 4) return 0;
  return put_sdo(out, counter, CoeService::SdoRequest, expedited_command(1, value.size(), complete_access), index,
                 subindex, value, {});
}

std::size_t encode_sdo_download_value(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                      std::uint8_t subindex, std::uint32_t value, std::size_t size) noexcept {
  if (size == 0 || size > 4) return 0;
  std::array<std::uint8_t, 4> bytes{};
  put_u32(bytes, 0, value);
  return encode_sdo_download_expedited(out, counter, index, subindex, std::span<const std::uint8_t>(bytes).first(size));
}

std::size_t encode_sdo_download_normal(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                       std::uint8_t subindex, std::uint32_t complete_size,
                                       std::span<const std::uint8_t> data, bool complete_access) noexcept {
  if (data.size() > complete_size) return 0;
  std::array<std::uint8_t, 4> size{};
  put_u32(size, 0, complete_size);
  // ccs 1, s = 1, e = 0 [ETG.1000.6 §5.6.2.2]
  const auto cmd = static_cast<std::uint8_t>(0x21 | (complete_access ? kCa : 0));
  return put_sdo(out, counter, CoeService::SdoRequest, cmd, index, subindex, size, data);
}

std::size_t encode_sdo_download_segment(std::span<std::uint8_t> out, std::uint8_t counter, bool toggle, bool last,
                                        std::span<const std::uint8_t> data) noexcept {
  const auto cmd = static_cast<std::uint8_t>((toggle ? 0x10 : 0) | (last ? 0x01 : 0));  // ccs 0
  return put_segment(out, counter, CoeService::SdoRequest, cmd, data);
}

std::size_t encode_sdo_upload_request(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                      std::uint8_t subindex, bool complete_access) noexcept {
  const auto cmd = static_cast<std::uint8_t>(0x40 | (complete_access ? kCa : 0));  // ccs 2
  return put_sdo(out, counter, CoeService::SdoRequest, cmd, index, subindex, {}, {});
}

std::size_t encode_sdo_upload_segment_request(std::span<std::uint8_t> out, std::uint8_t counter, bool toggle) noexcept {
  const auto cmd = static_cast<std::uint8_t>(0x60 | (toggle ? 0x10 : 0));  // ccs 3
  return put_sdo(out, counter, CoeService::SdoRequest, cmd, 0, 0, {}, {});
}

std::size_t encode_sdo_abort(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                             std::uint8_t subindex, std::uint32_t abort_code) noexcept {
  std::array<std::uint8_t, 4> code{};
  put_u32(code, 0, abort_code);
  return put_sdo(out, counter, CoeService::SdoRequest, 0x80, index, subindex, code, {});
}

std::size_t encode_sdo_download_response(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                         std::uint8_t subindex, bool complete_access) noexcept {
  const auto cmd = static_cast<std::uint8_t>(0x60 | (complete_access ? kCa : 0));  // scs 3
  return put_sdo(out, counter, CoeService::SdoResponse, cmd, index, subindex, {}, {});
}

std::size_t encode_sdo_download_segment_response(std::span<std::uint8_t> out, std::uint8_t counter,
                                                 bool toggle) noexcept {
  const auto cmd = static_cast<std::uint8_t>(0x20 | (toggle ? 0x10 : 0));  // scs 1
  return put_sdo(out, counter, CoeService::SdoResponse, cmd, 0, 0, {}, {});
}

std::size_t encode_sdo_upload_expedited_response(std::span<std::uint8_t> out, std::uint8_t counter,
                                                 std::uint16_t index, std::uint8_t subindex,
                                                 std::span<const std::uint8_t> value, bool complete_access) noexcept {
  if (value.empty() || value.size() > 4) return 0;
  return put_sdo(out, counter, CoeService::SdoResponse, expedited_command(2, value.size(), complete_access), index,
                 subindex, value, {});
}

std::size_t encode_sdo_upload_normal_response(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                              std::uint8_t subindex, std::uint32_t complete_size,
                                              std::span<const std::uint8_t> data, bool complete_access) noexcept {
  if (data.size() > complete_size) return 0;
  std::array<std::uint8_t, 4> size{};
  put_u32(size, 0, complete_size);
  const auto cmd = static_cast<std::uint8_t>(0x41 | (complete_access ? kCa : 0));  // scs 2, s = 1
  return put_sdo(out, counter, CoeService::SdoResponse, cmd, index, subindex, size, data);
}

std::size_t encode_sdo_upload_segment_response(std::span<std::uint8_t> out, std::uint8_t counter, bool toggle,
                                               bool last, std::span<const std::uint8_t> data) noexcept {
  const auto cmd = static_cast<std::uint8_t>((toggle ? 0x10 : 0) | (last ? 0x01 : 0));  // scs 0
  return put_segment(out, counter, CoeService::SdoResponse, cmd, data);
}

// ---- Emergency --------------------------------------------------------------------------------

EmergencyView decode_emergency(std::span<const std::uint8_t> in) noexcept {
  EmergencyView e;
  const CoeView c = decode_coe(in);
  e.mailbox = c.mailbox;
  if (c.error != MailboxError::None) {
    e.error = c.error;
    return e;
  }
  if (c.service != static_cast<std::uint8_t>(CoeService::Emergency)) {
    e.error = MailboxError::UnexpectedService;
    return e;
  }
  if (c.body.size() < 8) {
    e.error = MailboxError::TruncatedEmergency;
    return e;
  }
  e.emergency.error_code = get_u16(c.body, 0);
  e.emergency.error_register = c.body[2];
  std::copy(c.body.begin() + 3, c.body.begin() + 8, e.emergency.data.begin());
  return e;
}

std::size_t encode_emergency(std::span<std::uint8_t> out, std::uint8_t counter, const CoeEmergency& e) noexcept {
  if (!put_coe(out, counter, CoeService::Emergency, 8)) return 0;
  put_u16(out, kSdoAt, e.error_code);
  out[kSdoAt + 2] = e.error_register;
  std::copy(e.data.begin(), e.data.end(), out.begin() + kSdoAt + 3);
  return kSdoAt + 8;
}

// ---- SDO information --------------------------------------------------------------------------

std::string_view to_string(SdoInfoOpcode o) noexcept {
  switch (o) {
    case SdoInfoOpcode::GetOdListRequest: return "get OD list request";
    case SdoInfoOpcode::GetOdListResponse: return "get OD list response";
    case SdoInfoOpcode::GetObjectDescriptionRequest: return "get object description request";
    case SdoInfoOpcode::GetObjectDescriptionResponse: return "get object description response";
    case SdoInfoOpcode::GetEntryDescriptionRequest: return "get entry description request";
    case SdoInfoOpcode::GetEntryDescriptionResponse: return "get entry description response";
    case SdoInfoOpcode::Error: return "SDO information error";
  }
  return "unknown SDO information opcode";
}

namespace {

constexpr std::size_t kInfoHeaderSize = 4;  // opcode + incomplete, reserved, fragments left u16

std::string_view text_of(std::span<const std::uint8_t> b) noexcept {
  return std::string_view(reinterpret_cast<const char*>(b.data()), b.size());
}

std::size_t value_bytes(std::uint16_t bit_length) noexcept { return (static_cast<std::size_t>(bit_length) + 7) / 8; }

// Mailbox + CoE + SDO info header; returns the offset of the info data or 0.
std::size_t put_info(std::span<std::uint8_t> out, std::uint8_t counter, SdoInfoOpcode op, bool incomplete,
                     std::uint16_t fragments_left, std::size_t data) noexcept {
  if (!put_coe(out, counter, CoeService::SdoInformation, kInfoHeaderSize + data)) return 0;
  out[kSdoAt] = static_cast<std::uint8_t>(static_cast<unsigned>(op) | (incomplete ? 0x80U : 0U));
  out[kSdoAt + 1] = 0;
  put_u16(out, kSdoAt + 2, fragments_left);
  return kSdoAt + kInfoHeaderSize;
}

}  // namespace

SdoInfoView decode_sdo_info(std::span<const std::uint8_t> in, bool first_fragment) noexcept {
  SdoInfoView v;
  const CoeView c = decode_coe(in);
  v.mailbox = c.mailbox;
  auto fail = [&v](MailboxError e) {
    v.error = e;
    return v;
  };
  if (c.error != MailboxError::None) return fail(c.error);
  if (c.service != static_cast<std::uint8_t>(CoeService::SdoInformation)) return fail(MailboxError::UnexpectedService);
  if (c.body.size() < kInfoHeaderSize) return fail(MailboxError::TruncatedSdoInfo);
  const std::uint8_t op = static_cast<std::uint8_t>(c.body[0] & 0x7F);
  if (op < 1 || op > 7) return fail(MailboxError::UnknownSdoInfoOpcode);
  v.opcode = static_cast<SdoInfoOpcode>(op);
  v.incomplete = (c.body[0] & 0x80) != 0;
  v.fragments_left = get_u16(c.body, 2);
  const auto d = c.body.subspan(kInfoHeaderSize);
  switch (v.opcode) {
    case SdoInfoOpcode::GetOdListRequest:
      if (d.size() < 2) return fail(MailboxError::TruncatedSdoInfo);
      v.has_list_type = true;
      v.list_type = get_u16(d, 0);
      break;
    case SdoInfoOpcode::GetOdListResponse: {
      std::size_t at = 0;
      if (first_fragment) {
        if (d.size() < 2) return fail(MailboxError::TruncatedSdoInfo);
        v.has_list_type = true;
        v.list_type = get_u16(d, 0);
        at = 2;
      }
      const std::size_t n = (d.size() - at) / 2;  // an odd trailing byte is not an index
      v.index_bytes = d.subspan(at, 2 * n);
      break;
    }
    case SdoInfoOpcode::GetObjectDescriptionRequest:
      if (d.size() < 2) return fail(MailboxError::TruncatedSdoInfo);
      v.object.index = get_u16(d, 0);
      break;
    case SdoInfoOpcode::GetObjectDescriptionResponse:
      // index u16, data type u16, max subindex u8, object code u8, name
      if (d.size() < 6) return fail(MailboxError::TruncatedSdoInfo);
      v.object.index = get_u16(d, 0);
      v.object.data_type = get_u16(d, 2);
      v.object.max_subindex = d[4];
      v.object.object_code = d[5];
      v.object.name = text_of(d.subspan(6));
      break;
    case SdoInfoOpcode::GetEntryDescriptionRequest:
      if (d.size() < 4) return fail(MailboxError::TruncatedSdoInfo);
      v.entry.index = get_u16(d, 0);
      v.entry.subindex = d[2];
      v.entry.value_info = d[3];
      break;
    case SdoInfoOpcode::GetEntryDescriptionResponse: {
      // index u16, subindex u8, value info u8, data type u16, bit length u16, access u16, then
      // [unit type u32] [default] [minimum] [maximum] as flagged, then the name.
      if (d.size() < 10) return fail(MailboxError::TruncatedSdoInfo);
      auto& e = v.entry;
      e.index = get_u16(d, 0);
      e.subindex = d[2];
      e.value_info = d[3];
      e.data_type = get_u16(d, 4);
      e.bit_length = get_u16(d, 6);
      e.object_access = get_u16(d, 8);
      std::size_t at = 10;
      if (e.value_info & value_info::kUnitType) {
        if (d.size() - at < 4) return fail(MailboxError::TruncatedSdoInfo);
        e.unit_type = get_u32(d, at);
        at += 4;
      }
      const std::size_t vb = value_bytes(e.bit_length);
      for (auto [flag, field] : {std::pair{value_info::kDefault, &e.default_value},
                                 std::pair{value_info::kMinimum, &e.minimum},
                                 std::pair{value_info::kMaximum, &e.maximum}}) {
        if (e.value_info & flag) {
          if (d.size() - at < vb) return fail(MailboxError::TruncatedSdoInfo);
          *field = d.subspan(at, vb);
          at += vb;
        }
      }
      e.name = text_of(d.subspan(at));
      break;
    }
    case SdoInfoOpcode::Error:
      if (d.size() < 4) return fail(MailboxError::TruncatedSdoInfo);
      v.abort_code = get_u32(d, 0);
      break;
  }
  return v;
}

std::size_t encode_get_od_list_request(std::span<std::uint8_t> out, std::uint8_t counter, OdListType type) noexcept {
  const std::size_t at = put_info(out, counter, SdoInfoOpcode::GetOdListRequest, false, 0, 2);
  if (at == 0) return 0;
  put_u16(out, at, static_cast<std::uint16_t>(type));
  return at + 2;
}

std::size_t encode_get_object_description_request(std::span<std::uint8_t> out, std::uint8_t counter,
                                                  std::uint16_t index) noexcept {
  const std::size_t at = put_info(out, counter, SdoInfoOpcode::GetObjectDescriptionRequest, false, 0, 2);
  if (at == 0) return 0;
  put_u16(out, at, index);
  return at + 2;
}

std::size_t encode_get_entry_description_request(std::span<std::uint8_t> out, std::uint8_t counter,
                                                 std::uint16_t index, std::uint8_t subindex,
                                                 std::uint8_t value_info_flags) noexcept {
  const std::size_t at = put_info(out, counter, SdoInfoOpcode::GetEntryDescriptionRequest, false, 0, 4);
  if (at == 0) return 0;
  put_u16(out, at, index);
  out[at + 2] = subindex;
  out[at + 3] = value_info_flags;
  return at + 4;
}

std::size_t encode_get_od_list_response(std::span<std::uint8_t> out, std::uint8_t counter, OdListType type,
                                        bool first, std::uint16_t fragments_left,
                                        std::span<const std::uint16_t> indexes) noexcept {
  const std::size_t data = (first ? 2 : 0) + 2 * indexes.size();
  std::size_t at = put_info(out, counter, SdoInfoOpcode::GetOdListResponse, fragments_left > 0, fragments_left, data);
  if (at == 0) return 0;
  if (first) {
    put_u16(out, at, static_cast<std::uint16_t>(type));
    at += 2;
  }
  for (const std::uint16_t i : indexes) {
    put_u16(out, at, i);
    at += 2;
  }
  return at;
}

std::size_t encode_get_object_description_response(std::span<std::uint8_t> out, std::uint8_t counter,
                                                   const SdoInfoObjectDescription& d) noexcept {
  std::size_t at = put_info(out, counter, SdoInfoOpcode::GetObjectDescriptionResponse, false, 0, 6 + d.name.size());
  if (at == 0) return 0;
  put_u16(out, at, d.index);
  put_u16(out, at + 2, d.data_type);
  out[at + 4] = d.max_subindex;
  out[at + 5] = d.object_code;
  at += 6;
  for (const char ch : d.name) out[at++] = static_cast<std::uint8_t>(ch);
  return at;
}

std::size_t encode_get_entry_description_response(std::span<std::uint8_t> out, std::uint8_t counter,
                                                  const SdoInfoEntryDescription& d) noexcept {
  const std::size_t vb = value_bytes(d.bit_length);
  std::size_t data = 10 + d.name.size();
  if (d.value_info & value_info::kUnitType) data += 4;
  for (auto [flag, field] : {std::pair{value_info::kDefault, &d.default_value},
                             std::pair{value_info::kMinimum, &d.minimum}, std::pair{value_info::kMaximum, &d.maximum}}) {
    if (d.value_info & flag) {
      if (field->size() != vb) return 0;  // each value is exactly ceil(bit_length / 8) bytes
      data += vb;
    }
  }
  std::size_t at = put_info(out, counter, SdoInfoOpcode::GetEntryDescriptionResponse, false, 0, data);
  if (at == 0) return 0;
  put_u16(out, at, d.index);
  out[at + 2] = d.subindex;
  out[at + 3] = d.value_info;
  put_u16(out, at + 4, d.data_type);
  put_u16(out, at + 6, d.bit_length);
  put_u16(out, at + 8, d.object_access);
  at += 10;
  if (d.value_info & value_info::kUnitType) {
    put_u32(out, at, d.unit_type);
    at += 4;
  }
  for (auto [flag, field] : {std::pair{value_info::kDefault, &d.default_value},
                             std::pair{value_info::kMinimum, &d.minimum}, std::pair{value_info::kMaximum, &d.maximum}}) {
    if (d.value_info & flag) {
      std::copy(field->begin(), field->end(), out.begin() + static_cast<std::ptrdiff_t>(at));
      at += vb;
    }
  }
  for (const char ch : d.name) out[at++] = static_cast<std::uint8_t>(ch);
  return at;
}

std::size_t encode_sdo_info_error(std::span<std::uint8_t> out, std::uint8_t counter, std::uint32_t abort_code) noexcept {
  const std::size_t at = put_info(out, counter, SdoInfoOpcode::Error, false, 0, 4);
  if (at == 0) return 0;
  put_u32(out, at, abort_code);
  return at + 4;
}

}  // namespace drivegate::ethercat
