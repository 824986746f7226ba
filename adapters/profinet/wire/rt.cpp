#include "adapters/profinet/wire/rt.hpp"

#include <algorithm>

#include "adapters/profinet/wire/byte_order.hpp"

namespace drivegate::profinet {

void encode_apdu_status(const ApduStatus& s, std::span<std::uint8_t, kApduStatusSize> out) noexcept {
  put_be16(out, 0, s.cycle_counter);
  out[2] = s.data_status;
  out[3] = s.transfer_status;
}

ApduStatus decode_apdu_status(std::span<const std::uint8_t, kApduStatusSize> in) noexcept {
  ApduStatus s;
  s.cycle_counter = get_be16(in, 0);
  s.data_status = in[2];
  s.transfer_status = in[3];
  return s;
}

// ---- Layout -------------------------------------------------------------------------------------

std::string_view to_string(LayoutError e) noexcept {
  switch (e) {
    case LayoutError::None: return "no error";
    case LayoutError::TooLong: return "the IO data objects need more than 1440 octets (the largest C_SDU)";
    case LayoutError::TooFewPlacements: return "fewer placements than submodules";
    case LayoutError::BadSubmodule: return "a submodule has a data length for a direction its kind does not have";
  }
  return "?";
}

namespace {

bool has_input(IoKind k) noexcept { return k == IoKind::NoIo || k == IoKind::Input || k == IoKind::InputOutput; }
bool has_output(IoKind k) noexcept { return k == IoKind::Output || k == IoKind::InputOutput; }

}  // namespace

CsduLayout compute_csdu_layout(CrDirection direction, std::span<const IoSubmodule> submodules,
                               std::span<IoPlacement> placements) noexcept {
  CsduLayout l;
  if (placements.size() < submodules.size()) {
    l.error = LayoutError::TooFewPlacements;
    return l;
  }
  for (const IoSubmodule& s : submodules) {
    if ((s.input_length != 0 && !has_input(s.kind)) || (s.output_length != 0 && !has_output(s.kind)) ||
        (s.kind == IoKind::NoIo && s.input_length != 0)) {
      l.error = LayoutError::BadSubmodule;
      return l;
    }
  }
  const bool input_cr = direction == CrDirection::Input;
  std::size_t at = 0;
  auto fits = [&at](std::size_t n) { return at + n <= kMaxCsduLength; };
  // Provided data objects, each followed by its IOPS.
  for (std::size_t i = 0; i < submodules.size(); ++i) {
    const IoSubmodule& s = submodules[i];
    IoPlacement& p = placements[i];
    p = IoPlacement{};
    const bool provides = input_cr ? has_input(s.kind) : has_output(s.kind);
    if (!provides) continue;
    const std::uint16_t len = input_cr ? s.input_length : s.output_length;
    if (!fits(len + 1U)) {
      l.error = LayoutError::TooLong;
      return l;
    }
    p.data_offset = static_cast<std::uint16_t>(at);
    p.data_length = len;
    p.iops_offset = static_cast<std::uint16_t>(at + len);
    at += len + 1U;
  }
  // Consumer states for the data coming the other way.
  for (std::size_t i = 0; i < submodules.size(); ++i) {
    const IoSubmodule& s = submodules[i];
    const bool consumes = input_cr ? has_output(s.kind) : has_input(s.kind);
    if (!consumes) continue;
    if (!fits(1)) {
      l.error = LayoutError::TooLong;
      return l;
    }
    placements[i].iocs_offset = static_cast<std::uint16_t>(at);
    at += 1;
  }
  l.used = static_cast<std::uint16_t>(at);
  l.length = std::max(l.used, kMinCsduLength);
  return l;
}

// ---- Frames -------------------------------------------------------------------------------------

std::size_t encode_rt_cyclic(std::span<std::uint8_t> out, std::span<const std::uint8_t> c_sdu,
                             std::uint16_t c_sdu_length, const ApduStatus& status) noexcept {
  if (c_sdu_length < kMinCsduLength || c_sdu_length > kMaxCsduLength || c_sdu.size() > c_sdu_length ||
      out.size() < c_sdu_length + kApduStatusSize) {
    return 0;
  }
  std::copy(c_sdu.begin(), c_sdu.end(), out.begin());
  std::fill(out.begin() + static_cast<std::ptrdiff_t>(c_sdu.size()), out.begin() + c_sdu_length, std::uint8_t{0});
  encode_apdu_status(status, out.subspan(c_sdu_length).first<kApduStatusSize>());
  return c_sdu_length + kApduStatusSize;
}

std::string_view to_string(RtError e) noexcept {
  switch (e) {
    case RtError::None: return "no error";
    case RtError::BadCsduLength: return "C_SDU length outside 40..1440 octets";
    case RtError::Truncated: return "RT frame shorter than its C_SDU and APDU status";
  }
  return "?";
}

RtCyclicView decode_rt_cyclic(std::span<const std::uint8_t> pdu, std::uint16_t c_sdu_length) noexcept {
  RtCyclicView v;
  if (c_sdu_length < kMinCsduLength || c_sdu_length > kMaxCsduLength) {
    v.error = RtError::BadCsduLength;
    return v;
  }
  if (pdu.size() < c_sdu_length + kApduStatusSize) {
    v.error = RtError::Truncated;
    return v;
  }
  v.c_sdu = pdu.first(c_sdu_length);
  v.status = decode_apdu_status(pdu.subspan(c_sdu_length).first<kApduStatusSize>());
  return v;
}

std::string_view to_string(RtCheck c) noexcept {
  switch (c) {
    case RtCheck::Ok: return "ok";
    case RtCheck::WrongFrameId: return "FrameID is not the one of this input CR";
    case RtCheck::Truncated: return "frame shorter than the C_SDU length and APDU status";
    case RtCheck::TransferError: return "TransferStatus reports an error";
    case RtCheck::RepeatedCycle: return "cycle counter did not advance (repeated frame)";
    case RtCheck::OldCycle: return "cycle counter went back (old frame)";
    case RtCheck::Ignore: return "DataStatus says ignore";
    case RtCheck::DataInvalid: return "DataStatus says the data is invalid";
    case RtCheck::Backup: return "DataStatus says backup (not the primary AR)";
    case RtCheck::ProviderStop: return "the device's provider is in STOP";
  }
  return "?";
}

RtInputCheck check_input_frame(std::uint16_t frame_id, std::span<const std::uint8_t> pdu, std::uint16_t expected_frame_id,
                               std::uint16_t c_sdu_length, bool has_last, std::uint16_t last_cycle_counter) noexcept {
  RtInputCheck c;
  if (frame_id != expected_frame_id) {
    c.result = RtCheck::WrongFrameId;
    return c;
  }
  const RtCyclicView v = decode_rt_cyclic(pdu, c_sdu_length);
  if (!v.ok()) {
    c.result = RtCheck::Truncated;
    return c;
  }
  c.frame = v;
  c.station_problem = v.status.station_problem();
  if (v.status.transfer_status != 0) {
    c.result = RtCheck::TransferError;
  } else if (has_last && v.status.cycle_counter == last_cycle_counter) {
    c.result = RtCheck::RepeatedCycle;
  } else if (has_last && !cycle_counter_advanced(last_cycle_counter, v.status.cycle_counter)) {
    c.result = RtCheck::OldCycle;
  } else if (v.status.ignore()) {
    c.result = RtCheck::Ignore;
  } else if (!v.status.data_valid()) {
    c.result = RtCheck::DataInvalid;
  } else if (!v.status.primary()) {
    c.result = RtCheck::Backup;
  } else if (!v.status.provider_run()) {
    c.result = RtCheck::ProviderStop;
  }
  return c;
}

}  // namespace drivegate::profinet
