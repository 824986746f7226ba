#include "adapters/canopen/wire/sdo_codec.hpp"

#include <algorithm>

#include "adapters/canopen/wire/can_frame.hpp"

namespace drivegate::canopen {
namespace {

SdoBytes with_object(std::uint8_t cs, ObjectId o) noexcept {
  SdoBytes b{};
  b[0] = cs;
  put_le(b, 1, 2, o.index);
  b[3] = o.sub;
  return b;
}

// An initiate or abort frame whose bytes 4..7 carry `size` bytes of `value`: a 4-byte count or
// code, or the data of an expedited transfer.
SdoBytes with_value(std::uint8_t cs, ObjectId o, std::uint32_t value, std::size_t size = 4) noexcept {
  auto b = with_object(cs, o);
  put_le(b, 4, size, value);
  return b;
}

// Expedited with size indicated: cs | n (bytes of 4..7 without data) in bits 3..2.
SdoBytes expedited(std::uint8_t cs, ObjectId o, std::uint32_t value, std::uint8_t size) noexcept {
  size = std::clamp<std::uint8_t>(size, 1, 4);
  return with_value(static_cast<std::uint8_t>(cs | ((4 - size) << 2)), o, value, size);
}

ObjectId object_of(std::span<const std::uint8_t> p) noexcept {
  return {static_cast<std::uint16_t>(get_le(p, 1, 2)), p[3]};
}

// Download and upload segments share one layout: toggle, n (bytes of 1..7 without data), c.
SdoBytes segment(bool toggle, std::span<const std::uint8_t> bytes, bool last) noexcept {
  SdoBytes b{};
  const auto n = bytes.size() > 7 ? std::size_t{7} : bytes.size();
  b[0] = static_cast<std::uint8_t>((toggle ? 0x10 : 0) | ((7 - n) << 1) | (last ? 1 : 0));
  for (std::size_t i = 0; i < n; ++i) b[1 + i] = bytes[i];
  return b;
}

// Initiate frames (download request, upload response) share the e/s/n layout.
void decode_initiate(std::span<const std::uint8_t> p, SdoMessage& m) noexcept {
  m.object = object_of(p);
  m.expedited = (p[0] & 0x02) != 0;
  m.size_indicated = (p[0] & 0x01) != 0;
  if (m.expedited) {
    // n (bits 3..2) = bytes of 4..7 that hold no data, valid only with s = 1 [CiA 301]. Without a
    // size all four bytes are handed up; the reader takes the length from the object's type (SD6
    // sends 42h: SD6 digest §6.4).
    const std::uint8_t unused = m.size_indicated ? static_cast<std::uint8_t>((p[0] >> 2) & 0x03) : 0;
    m.length = static_cast<std::uint8_t>(4 - unused);
    for (std::size_t i = 0; i < 4; ++i) m.data[i] = p[4 + i];
  } else {
    m.size = m.size_indicated ? get_le(p, 4, 4) : 0;
  }
}

void decode_segment(std::span<const std::uint8_t> p, SdoMessage& m) noexcept {
  m.toggle = (p[0] & 0x10) != 0;
  m.last = (p[0] & 0x01) != 0;
  m.length = static_cast<std::uint8_t>(7 - ((p[0] >> 1) & 0x07));
  for (std::size_t i = 0; i < 7; ++i) m.data[i] = p[1 + i];
}

void decode_abort(std::span<const std::uint8_t> p, SdoMessage& m) noexcept {
  m.command = SdoCommand::Abort;
  m.object = object_of(p);
  m.abort_code = get_le(p, 4, 4);
}

}  // namespace

const char* to_string(SdoDecodeError e) noexcept {
  switch (e) {
    case SdoDecodeError::None: return "none";
    case SdoDecodeError::WrongLength: return "SDO frame is not 8 bytes long";
    case SdoDecodeError::UnknownCommand: return "unknown SDO command specifier";
  }
  return "?";
}

SdoDecoded decode_sdo_request(std::span<const std::uint8_t> p) noexcept {
  SdoDecoded d;
  if (p.size() != 8) {
    d.error = SdoDecodeError::WrongLength;
    return d;
  }
  auto& m = d.message;
  switch (p[0] >> 5) {
    case 0:
      m.command = SdoCommand::DownloadSegmentRequest;
      decode_segment(p, m);
      break;
    case 1:
      m.command = SdoCommand::InitiateDownloadRequest;
      decode_initiate(p, m);
      break;
    case 2:
      m.command = SdoCommand::InitiateUploadRequest;
      m.object = object_of(p);
      break;
    case 3:
      m.command = SdoCommand::UploadSegmentRequest;
      m.toggle = (p[0] & 0x10) != 0;
      break;
    case 4: decode_abort(p, m); break;
    case 5:
    case 6:
      m.command = SdoCommand::Block;
      m.object = object_of(p);
      break;
    default: d.error = SdoDecodeError::UnknownCommand; break;
  }
  return d;
}

SdoDecoded decode_sdo_response(std::span<const std::uint8_t> p) noexcept {
  SdoDecoded d;
  if (p.size() != 8) {
    d.error = SdoDecodeError::WrongLength;
    return d;
  }
  auto& m = d.message;
  switch (p[0] >> 5) {
    case 0:
      m.command = SdoCommand::UploadSegmentResponse;
      decode_segment(p, m);
      break;
    case 1:
      m.command = SdoCommand::DownloadSegmentResponse;
      m.toggle = (p[0] & 0x10) != 0;
      break;
    case 2:
      m.command = SdoCommand::InitiateUploadResponse;
      decode_initiate(p, m);
      break;
    case 3:
      // 60h per CiA 301; the SD6 English manual draws 63h, so the low bits are ignored (SD6
      // digest §6.4, quirk 19).
      m.command = SdoCommand::InitiateDownloadResponse;
      m.object = object_of(p);
      break;
    case 4: decode_abort(p, m); break;
    case 5:
    case 6:
      m.command = SdoCommand::Block;
      m.object = object_of(p);
      break;
    default: d.error = SdoDecodeError::UnknownCommand; break;
  }
  return d;
}

SdoBytes sdo_upload_request(ObjectId o) noexcept { return with_object(0x40, o); }

SdoBytes sdo_download_expedited(ObjectId o, std::uint32_t value, std::uint8_t size) noexcept {
  return expedited(0x23, o, value, size);
}

SdoBytes sdo_download_initiate(ObjectId o, std::uint32_t total_size) noexcept { return with_value(0x21, o, total_size); }

SdoBytes sdo_download_segment(bool toggle, std::span<const std::uint8_t> bytes, bool last) noexcept {
  return segment(toggle, bytes, last);
}

SdoBytes sdo_upload_segment_request(bool toggle) noexcept {
  SdoBytes b{};
  b[0] = toggle ? 0x70 : 0x60;
  return b;
}

SdoBytes sdo_download_response(ObjectId o) noexcept { return with_object(0x60, o); }

SdoBytes sdo_download_segment_response(bool toggle) noexcept {
  SdoBytes b{};
  b[0] = toggle ? 0x30 : 0x20;
  return b;
}

SdoBytes sdo_upload_expedited_response(ObjectId o, std::uint32_t value, std::uint8_t size) noexcept {
  return expedited(0x43, o, value, size);
}

SdoBytes sdo_upload_initiate_response(ObjectId o, std::uint32_t total_size) noexcept {
  return with_value(0x41, o, total_size);
}

SdoBytes sdo_upload_segment(bool toggle, std::span<const std::uint8_t> bytes, bool last) noexcept {
  return segment(toggle, bytes, last);
}

SdoBytes sdo_abort(ObjectId o, std::uint32_t code) noexcept { return with_value(0x80, o, code); }

}  // namespace drivegate::canopen
