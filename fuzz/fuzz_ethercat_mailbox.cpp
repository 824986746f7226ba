// The mailbox decoders (adapters/ethercat/wire/mailbox.hpp) on whatever a slave's SM1 holds:
// decode_mailbox, decode_coe, decode_sdo_request/response, decode_emergency, decode_sdo_info and
// decode_mailbox_error. Invariants: every view lies inside the input; a decoded SDO re-encodes
// (with the encoder for its command) into bytes that decode to the same command, object, flags,
// data and abort code; an emergency re-encodes to the same emergency.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>

#include "adapters/ethercat/wire/mailbox.hpp"

namespace {

using namespace drivegate::ethercat;

std::span<const std::uint8_t> input;

void inside(std::span<const std::uint8_t> s) {
  if (s.empty()) return;
  if (s.data() < input.data() || s.data() + s.size() > input.data() + input.size()) std::abort();
}
void inside(std::string_view s) {
  inside(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
}

std::size_t encode(std::span<std::uint8_t> out, const CoeSdo& s, std::uint8_t counter) {
  switch (s.command) {
    case SdoCommand::DownloadInitiateRequest:
      if (s.expedited) return encode_sdo_download_expedited(out, counter, s.index, s.subindex, s.data, s.complete_access);
      if (!s.size_indicated) return 0;
      return encode_sdo_download_normal(out, counter, s.index, s.subindex, s.size, s.data, s.complete_access);
    case SdoCommand::DownloadSegmentRequest: return encode_sdo_download_segment(out, counter, s.toggle, s.last, s.data);
    case SdoCommand::UploadInitiateRequest:
      return encode_sdo_upload_request(out, counter, s.index, s.subindex, s.complete_access);
    case SdoCommand::UploadSegmentRequest: return encode_sdo_upload_segment_request(out, counter, s.toggle);
    case SdoCommand::DownloadInitiateResponse:
      return encode_sdo_download_response(out, counter, s.index, s.subindex, s.complete_access);
    case SdoCommand::DownloadSegmentResponse: return encode_sdo_download_segment_response(out, counter, s.toggle);
    case SdoCommand::UploadInitiateResponse:
      if (s.expedited) {
        return encode_sdo_upload_expedited_response(out, counter, s.index, s.subindex, s.data, s.complete_access);
      }
      if (!s.size_indicated) return 0;
      return encode_sdo_upload_normal_response(out, counter, s.index, s.subindex, s.size, s.data, s.complete_access);
    case SdoCommand::UploadSegmentResponse:
      return encode_sdo_upload_segment_response(out, counter, s.toggle, s.last, s.data);
    case SdoCommand::Abort: return encode_sdo_abort(out, counter, s.index, s.subindex, s.abort_code);
  }
  std::abort();
}

bool same(const CoeSdo& a, const CoeSdo& b) {
  if (a.command != b.command || !std::equal(a.data.begin(), a.data.end(), b.data.begin(), b.data.end())) return false;
  switch (a.command) {
    case SdoCommand::DownloadSegmentRequest:
    case SdoCommand::UploadSegmentResponse: return a.toggle == b.toggle && a.last == b.last;
    case SdoCommand::UploadSegmentRequest:
    case SdoCommand::DownloadSegmentResponse: return a.toggle == b.toggle;
    case SdoCommand::Abort: return a.index == b.index && a.subindex == b.subindex && a.abort_code == b.abort_code;
    default:
      return a.index == b.index && a.subindex == b.subindex && a.complete_access == b.complete_access &&
             a.expedited == b.expedited && (a.expedited || a.size == b.size);
  }
}

void check_sdo(const SdoView& v, SdoView (*decode)(std::span<const std::uint8_t>)) {
  if (v.error != MailboxError::None) return;
  inside(v.sdo.data);
  // An expedited message without size indication carries 4 bytes; the encoder always indicates.
  static std::array<std::uint8_t, 4096 + 64> out{};
  const std::size_t n = encode(out, v.sdo, 1);
  if (n == 0) {
    // Only refusals the encoders document: a normal transfer without size.
    const bool normal_no_size = !v.sdo.expedited && !v.sdo.size_indicated &&
                                (v.sdo.command == SdoCommand::DownloadInitiateRequest ||
                                 v.sdo.command == SdoCommand::UploadInitiateResponse);
    if (!normal_no_size) std::abort();
    return;
  }
  const SdoView again = decode(std::span<const std::uint8_t>(out).first(n));
  if (again.error != MailboxError::None || !same(v.sdo, again.sdo)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  input = std::span<const std::uint8_t>(data, size);
  const MailboxView m = decode_mailbox(input);
  inside(m.payload);
  const CoeView c = decode_coe(input);
  inside(c.body);
  check_sdo(decode_sdo_request(input), decode_sdo_request);
  check_sdo(decode_sdo_response(input), decode_sdo_response);
  const EmergencyView e = decode_emergency(input);
  if (e.error == MailboxError::None) {
    std::array<std::uint8_t, 16> out{};
    const std::size_t n = encode_emergency(out, 1, e.emergency);
    if (n != 16 || decode_emergency(out).emergency != e.emergency) std::abort();
  }
  for (const bool first : {true, false}) {
    const SdoInfoView i = decode_sdo_info(input, first);
    if (i.error == MailboxError::None) {
      inside(i.index_bytes);
      inside(i.object.name);
      inside(i.entry.name);
      inside(i.entry.default_value);
      inside(i.entry.minimum);
      inside(i.entry.maximum);
      for (std::size_t k = 0; k < i.index_count(); ++k) (void)i.index_at(k);
    }
  }
  (void)decode_mailbox_error(input);
  return 0;
}
