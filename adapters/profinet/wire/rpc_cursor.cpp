#include "adapters/profinet/wire/rpc_cursor.hpp"

#include <algorithm>

namespace drivegate::profinet {

std::string_view to_string(WireError e) noexcept {
  switch (e) {
    case WireError::None: return "no error";
    case WireError::Truncated: return "message ends inside a field";
    case WireError::BufferTooSmall: return "output buffer too small";
    case WireError::InvalidArgument: return "value does not fit the layout";
    case WireError::BadRpcVersion: return "DCE/RPC version is not 4 (connectionless)";
    case WireError::UnknownPacketType: return "unknown DCE/RPC packet type";
    case WireError::UnsupportedDrep: return "unsupported data representation (drep)";
    case WireError::FragmentLengthBeyondData: return "DCE/RPC fragment length runs past the datagram";
    case WireError::UnexpectedPacketType: return "unexpected DCE/RPC packet type";
    case WireError::UnexpectedInterface: return "not the PNIO interface";
    case WireError::UnexpectedOpnum: return "unexpected PNIO operation number";
    case WireError::ArgsLengthBeyondData: return "NDR ArgsLength runs past the data";
    case WireError::NdrCountsInconsistent: return "NDR MaximumCount/Offset/ActualCount disagree with ArgsLength";
    case WireError::BlockLengthTooShort: return "BlockLength shorter than the block's fields";
    case WireError::BlockLengthBeyondData: return "BlockLength runs past the data";
    case WireError::BlockLengthMismatch: return "block fields do not end where BlockLength says";
    case WireError::WrongBlockType: return "unexpected block type";
    case WireError::UnsupportedBlockVersion: return "unsupported BlockVersionHigh";
    case WireError::CountBeyondData: return "a count needs more bytes than the block holds";
    case WireError::BadDataDescription: return "DataDescription is neither input nor output";
    case WireError::DuplicateBlock: return "block appears twice";
    case WireError::TooManyBlocks: return "more blocks than expected";
    case WireError::MissingBlock: return "a required block is missing";
  }
  return "?";
}

bool Reader::take(std::size_t n) noexcept {
  if (!ok()) return false;
  if (n > remaining()) {
    fail(WireError::Truncated);
    return false;
  }
  return true;
}

std::uint8_t Reader::u8() noexcept {
  if (!take(1)) return 0;
  return in_[pos_++];
}

std::uint16_t Reader::u16() noexcept {
  if (!take(2)) return 0;
  const std::uint16_t a = in_[pos_];
  const std::uint16_t b = in_[pos_ + 1];
  pos_ += 2;
  return order_ == ByteOrder::Big ? static_cast<std::uint16_t>((a << 8) | b) : static_cast<std::uint16_t>((b << 8) | a);
}

std::uint32_t Reader::u32() noexcept {
  if (!take(4)) return 0;
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const std::size_t at = order_ == ByteOrder::Big ? pos_ + i : pos_ + 3 - i;
    v = (v << 8) | in_[at];
  }
  pos_ += 4;
  return v;
}

Uuid Reader::uuid() noexcept {
  Uuid u;
  if (!take(kUuidSize)) return u;
  u.time_low = u32();
  u.time_mid = u16();
  u.time_hi_and_version = u16();
  std::copy_n(in_.begin() + static_cast<std::ptrdiff_t>(pos_), 8, u.clock_seq_node.begin());
  pos_ += 8;
  return u;
}

MacAddress Reader::mac() noexcept {
  MacAddress m{};
  const auto b = bytes(m.size());
  if (b.size() == m.size()) std::copy(b.begin(), b.end(), m.begin());
  return m;
}

std::span<const std::uint8_t> Reader::bytes(std::size_t n) noexcept {
  if (!take(n)) return {};
  const auto s = in_.subspan(pos_, n);
  pos_ += n;
  return s;
}

std::uint8_t* Writer::take(std::size_t n) noexcept {
  if (!ok()) return nullptr;
  if (n > out_.size() - pos_) {
    fail(WireError::BufferTooSmall);
    return nullptr;
  }
  std::uint8_t* p = out_.data() + pos_;
  pos_ += n;
  return p;
}

void Writer::u8(std::uint8_t v) noexcept {
  if (std::uint8_t* p = take(1)) *p = v;
}

void Writer::u16(std::uint16_t v) noexcept {
  if (take(2) != nullptr) patch_u16(pos_ - 2, v);
}

void Writer::u32(std::uint32_t v) noexcept {
  if (take(4) != nullptr) patch_u32(pos_ - 4, v);
}

void Writer::uuid(const Uuid& u) noexcept {
  u32(u.time_low);
  u16(u.time_mid);
  u16(u.time_hi_and_version);
  bytes(u.clock_seq_node);
}

void Writer::mac(const MacAddress& m) noexcept { bytes(m); }

void Writer::bytes(std::span<const std::uint8_t> b) noexcept {
  if (std::uint8_t* p = take(b.size())) std::copy(b.begin(), b.end(), p);
}

void Writer::text(std::string_view s) noexcept {
  if (std::uint8_t* p = take(s.size())) {
    for (const char c : s) *p++ = static_cast<std::uint8_t>(c);
  }
}

void Writer::zeros(std::size_t n) noexcept {
  if (std::uint8_t* p = take(n)) std::fill_n(p, n, std::uint8_t{0});
}

void Writer::patch_u16(std::size_t at, std::uint16_t v) noexcept {
  if (at + 2 > out_.size()) return;
  const auto hi = static_cast<std::uint8_t>(v >> 8);
  const auto lo = static_cast<std::uint8_t>(v & 0xFF);
  out_[at] = order_ == ByteOrder::Big ? hi : lo;
  out_[at + 1] = order_ == ByteOrder::Big ? lo : hi;
}

void Writer::patch_u32(std::size_t at, std::uint32_t v) noexcept {
  if (at + 4 > out_.size()) return;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto byte = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFF);
    out_[order_ == ByteOrder::Big ? at + 3 - i : at + i] = byte;
  }
}

}  // namespace drivegate::profinet
