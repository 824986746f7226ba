#pragma once
// The cursor the DCE/RPC and PNIO block codecs read and write with: a position in a span, an
// explicit byte order per message, and a sticky first error (every later access is a no-op that
// returns 0, so a decoder reads field after field and checks once).
//
// Byte order is per message because connectionless DCE/RPC carries it in the header: drep byte 0
// high nibble 0 = big-endian, 1 = little-endian [DCE 1.1 RPC §12.6.3.1, §14.2.5]; the RPC header
// fields and the NDR part follow it, while the PNIO blocks inside are always big-endian
// [IEC 61158-6-10 §5.1 "Coding of the fields": Unsigned16/32 transferred most significant octet
// first].
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::profinet {

enum class ByteOrder : std::uint8_t { Little, Big };

// Everything a PROFINET RPC or block codec can refuse, with a text a person can act on.
enum class WireError : std::uint8_t {
  None,
  Truncated,                 // the input ends inside a field
  BufferTooSmall,            // encoder: the output span is too small
  InvalidArgument,           // encoder: a value the layout cannot carry (too long, too many)
  BadRpcVersion,             // RPC header version is not 4
  UnknownPacketType,         // RPC packet type outside 0..10
  UnsupportedDrep,           // drep: integer representation other than 0/1, or not ASCII
  FragmentLengthBeyondData,  // RPC fragment length runs past the datagram
  UnexpectedPacketType,      // e.g. a request where a response is expected
  UnexpectedInterface,       // not the PNIO device/controller interface
  UnexpectedOpnum,           // e.g. not Connect in a Connect response
  ArgsLengthBeyondData,      // NDR ArgsLength larger than the bytes that follow
  NdrCountsInconsistent,     // NDR MaximumCount/Offset/ActualCount disagree with ArgsLength
  BlockLengthTooShort,       // BlockLength below the fixed fields of the block type
  BlockLengthBeyondData,     // BlockLength runs past the input
  BlockLengthMismatch,       // the fields do not end where BlockLength says
  WrongBlockType,            // not the block type the decoder handles
  UnsupportedBlockVersion,   // BlockVersionHigh other than 1
  CountBeyondData,           // a NumberOf... count needs more bytes than the block holds
  BadDataDescription,        // ExpectedSubmodule: DataDescription type not 1 (input) / 2 (output)
  DuplicateBlock,            // Connect response: a second ARBlockRes/AlarmCRBlockRes/ModuleDiffBlock
  TooManyBlocks,             // Connect response: more IOCRBlockRes than the view holds
  MissingBlock,              // Connect response: no ARBlockRes although the status is OK
};
std::string_view to_string(WireError e) noexcept;

// A DCE UUID [DCE 1.1 RPC Appendix A]: time_low, time_mid, time_hi_and_version are numbers and
// follow the message's byte order; clock_seq and node are octets, always in this order.
struct Uuid {
  std::uint32_t time_low = 0;
  std::uint16_t time_mid = 0;
  std::uint16_t time_hi_and_version = 0;
  std::array<std::uint8_t, 8> clock_seq_node{};
  bool operator==(const Uuid&) const = default;
  [[nodiscard]] bool is_nil() const noexcept { return *this == Uuid{}; }
};
inline constexpr std::size_t kUuidSize = 16;

using MacAddress = std::array<std::uint8_t, 6>;

class Reader {
 public:
  Reader(std::span<const std::uint8_t> in, ByteOrder order) noexcept : in_(in), order_(order) {}

  std::uint8_t u8() noexcept;
  std::uint16_t u16() noexcept;
  std::uint32_t u32() noexcept;
  Uuid uuid() noexcept;
  MacAddress mac() noexcept;
  // A view of the next `n` bytes (empty after an error).
  std::span<const std::uint8_t> bytes(std::size_t n) noexcept;
  void skip(std::size_t n) noexcept { (void)bytes(n); }

  // Records `e` unless an error is already recorded: the first error wins.
  void fail(WireError e) noexcept {
    if (error_ == WireError::None) error_ = e;
  }
  [[nodiscard]] bool ok() const noexcept { return error_ == WireError::None; }
  [[nodiscard]] WireError error() const noexcept { return error_; }
  [[nodiscard]] std::size_t position() const noexcept { return pos_; }
  [[nodiscard]] std::size_t remaining() const noexcept { return in_.size() - pos_; }
  [[nodiscard]] ByteOrder order() const noexcept { return order_; }
  void set_order(ByteOrder o) noexcept { order_ = o; }

 private:
  bool take(std::size_t n) noexcept;
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
  ByteOrder order_;
  WireError error_ = WireError::None;
};

class Writer {
 public:
  Writer(std::span<std::uint8_t> out, ByteOrder order) noexcept : out_(out), order_(order) {}

  void u8(std::uint8_t v) noexcept;
  void u16(std::uint16_t v) noexcept;
  void u32(std::uint32_t v) noexcept;
  void uuid(const Uuid& u) noexcept;
  void mac(const MacAddress& m) noexcept;
  void bytes(std::span<const std::uint8_t> b) noexcept;
  void text(std::string_view s) noexcept;
  void zeros(std::size_t n) noexcept;
  // Overwrites a number written earlier at `at` (lengths known only at the end).
  void patch_u16(std::size_t at, std::uint16_t v) noexcept;
  void patch_u32(std::size_t at, std::uint32_t v) noexcept;

  void fail(WireError e) noexcept {
    if (error_ == WireError::None) error_ = e;
  }
  [[nodiscard]] bool ok() const noexcept { return error_ == WireError::None; }
  [[nodiscard]] WireError error() const noexcept { return error_; }
  [[nodiscard]] std::size_t position() const noexcept { return pos_; }
  // Bytes written, or 0 after an error: what the encoders return.
  [[nodiscard]] std::size_t size_or_zero() const noexcept { return ok() ? pos_ : 0; }
  [[nodiscard]] ByteOrder order() const noexcept { return order_; }

 private:
  std::uint8_t* take(std::size_t n) noexcept;
  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  ByteOrder order_;
  WireError error_ = WireError::None;
};

}  // namespace drivegate::profinet
