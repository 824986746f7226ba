// The RT class 1 codecs (adapters/profinet/wire/rt.hpp). Byte 0 picks the part:
//   even: C_SDU length (bytes 1-2, big-endian), last cycle counter (bytes 3-4), then a frame for
//         decode_ethernet + check_input_frame + decode_rt_cyclic. Invariants: the C_SDU view lies
//         inside the frame with the length asked for; a decoded frame re-encodes byte for byte
//         (C_SDU and APDU status); the check reports Ok only for a valid, primary, RUN frame with
//         a new cycle counter.
//   odd:  records (kind u8, input length u16, output length u16) for compute_csdu_layout in both
//         directions. Invariants: every object inside the used length, no two objects overlap,
//         used <= 1440, length = max(used, 40).
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adapters/profinet/wire/ethernet.hpp"
#include "adapters/profinet/wire/rt.hpp"

namespace {

using namespace drivegate::profinet;

void frame_part(std::span<const std::uint8_t> in) {
  if (in.size() < 4) return;
  const auto c_sdu_length = static_cast<std::uint16_t>((in[0] << 8) | in[1]);
  const auto last = static_cast<std::uint16_t>((in[2] << 8) | in[3]);
  const std::span<const std::uint8_t> frame = in.subspan(4);
  const EthernetView e = decode_ethernet(frame);
  if (!e.ok()) return;
  const RtCyclicView v = decode_rt_cyclic(e.pdu, c_sdu_length);
  if (v.ok()) {
    if (v.c_sdu.size() != c_sdu_length || v.c_sdu.data() != e.pdu.data()) std::abort();
    static std::array<std::uint8_t, kMaxCsduLength + kApduStatusSize> out{};
    const std::size_t n = encode_rt_cyclic(out, v.c_sdu, c_sdu_length, v.status);
    if (n != c_sdu_length + kApduStatusSize) std::abort();
    for (std::size_t i = 0; i < n; ++i) {
      if (out[i] != e.pdu[i]) std::abort();
    }
  }
  const RtInputCheck c = check_input_frame(e.header.frame_id, e.pdu, e.header.frame_id, c_sdu_length, true, last);
  if (c.result == RtCheck::Ok) {
    const ApduStatus& s = c.frame.status;
    if (!v.ok() || !s.data_valid() || !s.primary() || !s.provider_run() || s.ignore() || s.transfer_status != 0 ||
        !cycle_counter_advanced(last, s.cycle_counter)) {
      std::abort();
    }
  }
}

void layout_part(std::span<const std::uint8_t> in) {
  std::array<IoSubmodule, 64> subs{};
  std::size_t n = 0;
  for (std::size_t at = 0; at + 5 <= in.size() && n < subs.size(); at += 5) {
    subs[n].kind = static_cast<IoKind>(in[at] & 3);
    subs[n].input_length = static_cast<std::uint16_t>((in[at + 1] << 8) | in[at + 2]);
    subs[n].output_length = static_cast<std::uint16_t>((in[at + 3] << 8) | in[at + 4]);
    ++n;
  }
  for (const CrDirection d : {CrDirection::Input, CrDirection::Output}) {
    std::array<IoPlacement, 64> p{};
    const CsduLayout l = compute_csdu_layout(d, std::span(subs).first(n), p);
    if (!l.ok()) continue;
    if (l.used > kMaxCsduLength || l.length != (l.used < kMinCsduLength ? kMinCsduLength : l.used)) std::abort();
    std::array<bool, kMaxCsduLength> taken{};
    const auto claim = [&](std::uint16_t offset, std::size_t len) {
      if (offset == kNoOffset) return;
      if (offset + len > l.used) std::abort();
      for (std::size_t i = offset; i < offset + len; ++i) {
        if (taken[i]) std::abort();
        taken[i] = true;
      }
    };
    std::size_t objects = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if ((p[i].data_offset == kNoOffset) != (p[i].iops_offset == kNoOffset)) std::abort();
      claim(p[i].data_offset, p[i].data_length);
      claim(p[i].iops_offset, 1);
      claim(p[i].iocs_offset, 1);
      objects += (p[i].data_offset != kNoOffset ? p[i].data_length + 1U : 0U) + (p[i].iocs_offset != kNoOffset ? 1U : 0U);
    }
    if (objects != l.used) std::abort();  // no gaps either
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0 || size > 4096) return 0;
  const std::span<const std::uint8_t> in(data + 1, size - 1);
  if ((data[0] & 1) == 0) {
    frame_part(in);
  } else {
    layout_part(in);
  }
  return 0;
}
