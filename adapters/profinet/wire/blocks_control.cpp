#include "adapters/profinet/wire/blocks_control.hpp"

#include <array>

namespace drivegate::profinet {

namespace {
constexpr std::array<std::uint16_t, 6> kControlTypes{
    block_type::kPrmEndReq,  block_type::kApplicationReadyReq, block_type::kReleaseReq,
    block_type::kPrmEndRes,  block_type::kApplicationReadyRes, block_type::kReleaseRes,
};
}  // namespace

std::size_t encode_control_block(const ControlBlock& b, std::span<std::uint8_t> out) noexcept {
  bool known = false;
  for (const std::uint16_t t : kControlTypes) known = known || t == b.type;
  if (!known) return 0;
  Writer w(out, ByteOrder::Big);
  const std::size_t start = begin_block(w, b.type);
  w.u16(0);  // reserved
  w.uuid(b.ar_uuid);
  w.u16(b.session_key);
  w.u16(b.alarm_sequence_number);
  w.u16(b.command);
  w.u16(b.properties);
  end_block(w, start);
  return w.size_or_zero();
}

ControlBlockView decode_control_block(std::span<const std::uint8_t> in) noexcept {
  ControlBlockView v;
  const BlockBody bb = open_block_of(in, kControlTypes, kControlBlockSize - kBlockHeaderSize);
  if (bb.error != WireError::None) {
    v.error = bb.error;
    return v;
  }
  Reader r(bb.body, ByteOrder::Big);
  v.block.type = bb.header.type;
  r.skip(2);
  v.block.ar_uuid = r.uuid();
  v.block.session_key = r.u16();
  v.block.alarm_sequence_number = r.u16();
  v.block.command = r.u16();
  v.block.properties = r.u16();
  v.error = finish_block(r);
  v.size = bb.size;
  return v;
}

ControlBlock control_response_for(const ControlBlock& request) noexcept {
  ControlBlock b = request;
  b.type = static_cast<std::uint16_t>(request.type | 0x8000);
  b.command = control_command::kDone;
  b.properties = 0;
  return b;
}

}  // namespace drivegate::profinet
