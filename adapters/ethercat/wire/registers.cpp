#include "adapters/ethercat/wire/registers.hpp"

#include "core/bytes.hpp"

namespace drivegate::ethercat {

using core::get_u16;
using core::get_u32;
using core::put_u16;
using core::put_u32;

std::string_view to_string(AlState s) noexcept {
  switch (s) {
    case AlState::None: return "NONE";
    case AlState::Init: return "INIT";
    case AlState::PreOp: return "PRE-OP";
    case AlState::Boot: return "BOOT";
    case AlState::SafeOp: return "SAFE-OP";
    case AlState::Op: return "OP";
  }
  return "unknown";
}

bool is_valid_state(std::uint8_t raw) noexcept {
  return raw == 1 || raw == 2 || raw == 3 || raw == 4 || raw == 8;
}

AlStatus decode_al_status(std::uint16_t v) noexcept {
  AlStatus s;
  s.raw_state = static_cast<std::uint8_t>(v & kAlStateMask);
  s.error = (v & kAlErrorBit) != 0;
  s.identification = (v & kAlIdentBit) != 0;
  return s;
}

// FMMU layout [ETG.1000.4 Table 56]: logical start u32, length u16, logical start bit u8 (bits 0-2),
// logical stop bit u8 (bits 0-2), physical start u16, physical start bit u8 (bits 0-2), type u8
// (bit 0 read, bit 1 write), activate u8 (bit 0), 3 reserved bytes.
std::array<std::uint8_t, kFmmuEntrySize> encode_fmmu(const FmmuEntry& f) noexcept {
  std::array<std::uint8_t, kFmmuEntrySize> b{};
  put_u32(b, 0, f.logical_start);
  put_u16(b, 4, f.length);
  b[6] = static_cast<std::uint8_t>(f.logical_start_bit & 0x07);
  b[7] = static_cast<std::uint8_t>(f.logical_stop_bit & 0x07);
  put_u16(b, 8, f.physical_start);
  b[10] = static_cast<std::uint8_t>(f.physical_start_bit & 0x07);
  b[11] = static_cast<std::uint8_t>(f.type & 0x03);
  b[12] = f.active ? 1 : 0;
  return b;
}

std::optional<FmmuEntry> decode_fmmu(std::span<const std::uint8_t> in) noexcept {
  if (in.size() < kFmmuEntrySize) return std::nullopt;
  FmmuEntry f;
  f.logical_start = get_u32(in, 0);
  f.length = get_u16(in, 4);
  f.logical_start_bit = static_cast<std::uint8_t>(in[6] & 0x07);
  f.logical_stop_bit = static_cast<std::uint8_t>(in[7] & 0x07);
  f.physical_start = get_u16(in, 8);
  f.physical_start_bit = static_cast<std::uint8_t>(in[10] & 0x07);
  f.type = static_cast<std::uint8_t>(in[11] & 0x03);
  f.active = (in[12] & 0x01) != 0;
  return f;
}

// SyncManager layout [ETG.1000.4 Table 59]: physical start u16, length u16, control u8, status u8,
// activate u8, PDI control u8.
std::array<std::uint8_t, kSmEntrySize> encode_sm(const SmEntry& s) noexcept {
  std::array<std::uint8_t, kSmEntrySize> b{};
  put_u16(b, 0, s.physical_start);
  put_u16(b, 2, s.length);
  b[4] = s.control;
  b[5] = s.status;
  b[6] = s.activate;
  b[7] = s.pdi_control;
  return b;
}

std::optional<SmEntry> decode_sm(std::span<const std::uint8_t> in) noexcept {
  if (in.size() < kSmEntrySize) return std::nullopt;
  SmEntry s;
  s.physical_start = get_u16(in, 0);
  s.length = get_u16(in, 2);
  s.control = in[4];
  s.status = in[5];
  s.activate = in[6];
  s.pdi_control = in[7];
  return s;
}

}  // namespace drivegate::ethercat
