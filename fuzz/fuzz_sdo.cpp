// decode_sdo_request / decode_sdo_response (adapters/canopen/wire/sdo_codec.hpp) on payloads of
// 0..16 bytes: the SDO server and client parse whatever a CAN frame carries. Invariants: only
// 8-byte payloads decode; a decoded message has at most 7 data bytes (4 when expedited); and the
// encoder for that message produces bytes that decode to the same message (command, object,
// toggle, last, data, abort code, and the size where one is indicated).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace {

using namespace drivegate::canopen;

// The message as its own encoder writes it.
SdoBytes encode(const SdoMessage& m) {
  const std::span<const std::uint8_t> bytes(m.data.data(), m.length);
  // Only expedited messages carry a value (1..4 bytes); get_le takes at most 4.
  const std::uint32_t value = m.expedited ? get_le(bytes, 0, m.length) : 0;
  switch (m.command) {
    case SdoCommand::DownloadSegmentRequest: return sdo_download_segment(m.toggle, bytes, m.last);
    case SdoCommand::InitiateDownloadRequest:
      return m.expedited ? sdo_download_expedited(m.object, value, m.length) : sdo_download_initiate(m.object, m.size);
    case SdoCommand::InitiateUploadRequest: return sdo_upload_request(m.object);
    case SdoCommand::UploadSegmentRequest: return sdo_upload_segment_request(m.toggle);
    case SdoCommand::UploadSegmentResponse: return sdo_upload_segment(m.toggle, bytes, m.last);
    case SdoCommand::DownloadSegmentResponse: return sdo_download_segment_response(m.toggle);
    case SdoCommand::InitiateUploadResponse:
      return m.expedited ? sdo_upload_expedited_response(m.object, value, m.length)
                         : sdo_upload_initiate_response(m.object, m.size);
    case SdoCommand::InitiateDownloadResponse: return sdo_download_response(m.object);
    case SdoCommand::Abort: return sdo_abort(m.object, m.abort_code);
    case SdoCommand::Block: break;
  }
  std::abort();
}

bool same(const SdoMessage& a, const SdoMessage& b) {
  if (a.command != b.command || a.length != b.length || a.expedited != b.expedited) return false;
  for (std::size_t i = 0; i < a.length; ++i) {
    if (a.data[i] != b.data[i]) return false;
  }
  switch (a.command) {
    case SdoCommand::DownloadSegmentRequest:
    case SdoCommand::UploadSegmentResponse: return a.toggle == b.toggle && a.last == b.last;
    case SdoCommand::UploadSegmentRequest:
    case SdoCommand::DownloadSegmentResponse: return a.toggle == b.toggle;
    case SdoCommand::InitiateDownloadRequest:
    case SdoCommand::InitiateUploadResponse:
      // The encoders always indicate the size; a message without it only keeps its object.
      return a.object == b.object && (!a.size_indicated || a.expedited || a.size == b.size);
    case SdoCommand::InitiateUploadRequest:
    case SdoCommand::InitiateDownloadResponse: return a.object == b.object;
    case SdoCommand::Abort: return a.object == b.object && a.abort_code == b.abort_code;
    case SdoCommand::Block: return true;
  }
  return false;
}

void check(const SdoDecoded& d, std::size_t size, SdoDecoded (*decode)(std::span<const std::uint8_t>)) {
  if (d.error != SdoDecodeError::None) return;
  const SdoMessage& m = d.message;
  if (size != 8 || m.length > 7 || (m.expedited && m.length > 4)) std::abort();
  if (m.command == SdoCommand::Block) return;  // recognised, never encoded
  const SdoBytes bytes = encode(m);
  const SdoDecoded again = decode(bytes);
  if (again.error != SdoDecodeError::None || !same(m, again.message)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16) return 0;
  const std::span<const std::uint8_t> payload(data, size);
  check(decode_sdo_request(payload), size, decode_sdo_request);
  check(decode_sdo_response(payload), size, decode_sdo_response);
  return 0;
}
