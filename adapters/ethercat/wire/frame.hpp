#pragma once
// EtherCAT frames on raw Ethernet [ETG.1000.4 §5.3-§5.4; IEEE 802.3 / 802.1Q]:
//
//   Ethernet II header   dst(6) src(6) [TPID 8100h + TCI (802.1Q tag, decode only)] EtherType 88A4h (big-endian)
//   EtherCAT header      u16 LE: bits 0-10 length of the datagrams, bit 11 reserved, bits 12-15 type
//                        (1 = EtherCAT commands / DLPDU; 4 network variables and 5 mailbox gateway
//                        are rejected) [ETG.1000.4 §5.3]
//   datagram × n         cmd(1) idx(1) address(4) len(2: bits 0-10 length, bit 14 C circulating,
//                        bit 15 M more datagrams follow) IRQ(2) | data(length) | WKC(2)
//                        [ETG.1000.4 §5.4]
//   padding              to the 60-byte Ethernet minimum (without FCS); not counted in the length
//
// The builder writes into a caller's buffer and the parser reads one in place: no allocation.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/ethercat/wire/ethernet.hpp"

namespace drivegate::ethercat {

using MacAddress = std::array<std::uint8_t, 6>;

// kEtherType, kVlanTpid, the header sizes and kMin/kMaxFrameSize: wire/ethernet.hpp.
inline constexpr std::size_t kDatagramHeaderSize = 10;
inline constexpr std::size_t kWkcSize = 2;
inline constexpr std::size_t kDatagramOverhead = kDatagramHeaderSize + kWkcSize;
inline constexpr std::uint16_t kMaxEcatLength = 0x7FF;  // 11-bit length field
// Largest data of one datagram in an untagged frame: 1514 - 14 - 2 - 12.
inline constexpr std::size_t kMaxDatagramData = kMaxFrameSize - kEthernetHeaderSize - kEcatHeaderSize - kDatagramOverhead;
// The most datagrams an untagged frame holds: each takes at least its header and WKC (a datagram
// without data), 1498 / 12 = 124. The protocol sets no other bound [ETG.1000.4 §5.3: datagrams
// follow each other while the M bit is set].
inline constexpr std::size_t kMaxDatagramsPerFrame =
    (kMaxFrameSize - kEthernetHeaderSize - kEcatHeaderSize) / kDatagramOverhead;
inline constexpr std::uint8_t kEcatTypeCommands = 1;  // ETG.1000.4 §5.3: type 1 = EtherCAT DLPDU

// Broadcast destination: EtherCAT slaves forward any destination; masters commonly use it.
inline constexpr MacAddress kBroadcastMac{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};

// Datagram commands [ETG.1000.4 §5.4, one clause per command (APRD: §5.4.1.2 Table 14)].
enum class Command : std::uint8_t {
  NOP = 0,
  APRD = 1,
  APWR = 2,
  APRW = 3,
  FPRD = 4,
  FPWR = 5,
  FPRW = 6,
  BRD = 7,
  BWR = 8,
  BRW = 9,
  LRD = 10,
  LWR = 11,
  LRW = 12,
  ARMW = 13,
  FRMW = 14,
};
inline constexpr std::uint8_t kCommandCount = 15;

constexpr bool is_valid_command(std::uint8_t raw) noexcept { return raw < kCommandCount; }

// "APRD" etc.; "?" for a value outside the enum.
std::string_view command_name(Command c) noexcept;
// "auto increment physical read" etc.
std::string_view command_description(Command c) noexcept;

enum class Addressing : std::uint8_t { None, AutoIncrement, Configured, Broadcast, Logical };
enum class Access : std::uint8_t { None, Read, Write, ReadWrite, ReadMultipleWrite };
Addressing addressing_of(Command c) noexcept;
Access access_of(Command c) noexcept;

// Address field: position addressing (APxx/ARMW, BRD..: ADP = position, ADO = register) or
// logical (LRD/LWR/LRW: one 32-bit address) [ETG.1000.4 §5.4].
constexpr std::uint32_t physical_address(std::uint16_t adp, std::uint16_t ado) noexcept {
  return static_cast<std::uint32_t>(adp) | (static_cast<std::uint32_t>(ado) << 16);
}
// Auto-increment ADP for the slave at `position` (0-based): each slave increments ADP and the one
// that sees 0 is addressed, so the master sends -position [ETG.1000.4 §5.4].
constexpr std::uint16_t auto_increment_adp(std::uint16_t position) noexcept {
  return static_cast<std::uint16_t>(0x10000U - position);
}

// Expected working counter [ETG.1000.4 §5.4, working counter of each command: read +1, write +1,
// read-write: read +1, write +2] for `slaves` slaves that each execute the command successfully. ARMW/FRMW: the
// addressed slave reads (+1), every other slave writes (+1), so each counts once.
std::uint16_t expected_wkc(Command c, std::uint16_t slaves) noexcept;
// Logical read/write over an image: `readers` slaves with inputs in the addressed range, `writers`
// with outputs (LRD counts readers, LWR writers, LRW readers + 2 × writers).
std::uint16_t expected_logical_wkc(Command c, std::uint16_t readers, std::uint16_t writers) noexcept;

struct DatagramHeader {
  Command command = Command::NOP;
  std::uint8_t index = 0;
  std::uint32_t address = 0;  // ADP in the low 16 bits, ADO in the high 16 bits, or logical
  std::uint16_t length = 0;   // data bytes, 0..2047 (11 bits)
  bool circulating = false;   // C bit (bit 14 of the length word)
  bool more = false;          // M bit (bit 15): another datagram follows
  std::uint16_t irq = 0;

  std::uint16_t adp() const noexcept { return static_cast<std::uint16_t>(address & 0xFFFF); }
  std::uint16_t ado() const noexcept { return static_cast<std::uint16_t>(address >> 16); }
};

// 10-byte header codec; `out`/`in` must hold 10 bytes (returns false otherwise).
bool encode_datagram_header(const DatagramHeader& h, std::span<std::uint8_t> out) noexcept;
bool decode_datagram_header(std::span<const std::uint8_t> in, DatagramHeader& h) noexcept;

// ---- Builder ----------------------------------------------------------------------------------

enum class BuildError : std::uint8_t {
  None,
  BufferTooSmall,  // the caller's buffer cannot hold even a minimum frame (60 bytes)
  FrameFull,       // the datagram does not fit in what is left of the buffer / 1514 bytes
  DataTooLong,     // data span longer than the datagram length, or length beyond 11 bits
  Finished,        // add() after finish()
};
std::string_view to_string(BuildError e) noexcept;

// Where a datagram sits in the built frame, for reading the answer back in place (the frame comes
// back with the same layout).
struct DatagramSlot {
  std::size_t header_offset = 0;
  std::size_t data_offset = 0;
  std::size_t wkc_offset = 0;
  std::uint16_t length = 0;
};

struct AddResult {
  BuildError error = BuildError::None;
  DatagramSlot slot{};
  bool ok() const noexcept { return error == BuildError::None; }
};

class FrameBuilder {
 public:
  // Writes the Ethernet and EtherCAT headers into `buffer` (frames never exceed 1514 bytes even
  // with a larger buffer). A buffer under 60 bytes leaves the builder in BufferTooSmall.
  FrameBuilder(std::span<std::uint8_t> buffer, const MacAddress& dst, const MacAddress& src) noexcept;

  // Appends one datagram: header, `data` copied into the start of its `length` bytes (the rest is
  // zero), WKC = `wkc` (0 for a master). Sets the M bit of the previous datagram.
  AddResult add(Command command, std::uint8_t index, std::uint32_t address, std::uint16_t length,
                std::span<const std::uint8_t> data = {}, std::uint16_t irq = 0, std::uint16_t wkc = 0) noexcept;

  // Data bytes one more datagram could carry (0 when not even an empty one fits).
  std::size_t remaining_data() const noexcept;
  std::size_t datagram_count() const noexcept { return count_; }
  BuildError error() const noexcept { return state_error_; }

  // Writes the EtherCAT length, zero-pads to 60 bytes and returns the frame (empty on error or
  // when no datagram was added). Later add() calls fail with Finished.
  std::span<std::uint8_t> finish() noexcept;

 private:
  std::size_t room() const noexcept;  // bytes left for datagrams (headers, data, WKCs)

  std::span<std::uint8_t> buf_;
  std::size_t pos_ = 0;
  std::size_t last_header_ = 0;
  std::size_t count_ = 0;
  bool finished_ = false;
  BuildError state_error_ = BuildError::None;
};

// ---- Parser -----------------------------------------------------------------------------------

enum class FrameError : std::uint8_t {
  None,
  TruncatedEthernet,     // shorter than the Ethernet header (or the VLAN tag)
  WrongEtherType,        // not 88A4h (after an optional 802.1Q tag)
  TruncatedEcatHeader,   // no room for the 2-byte EtherCAT header
  UnsupportedType,       // EtherCAT header type other than 1 (commands)
  EcatLengthBeyondFrame, // EtherCAT length larger than the bytes after its header
  EmptyFrame,            // EtherCAT length 0: no datagram
  TruncatedDatagramHeader,  // fewer than 10 bytes left within the EtherCAT length for a header
  DatagramBeyondLength,  // header's data length + WKC runs past the EtherCAT length
  UnknownCommand,        // CMD 15..255
  MoreBitWithoutDatagram,   // M set on a datagram that ends the EtherCAT length
  LengthAfterLastDatagram,  // M clear but bytes are left within the EtherCAT length
};
inline constexpr std::size_t kFrameErrorCount = 12;
std::string_view to_string(FrameError e) noexcept;

// Per-reason counters for rejected frames (the bus status reports them).
struct FrameErrorCounters {
  std::array<std::uint64_t, kFrameErrorCount> counts{};
  void count(FrameError e) noexcept { counts[static_cast<std::size_t>(e)]++; }
  std::uint64_t operator[](FrameError e) const noexcept { return counts[static_cast<std::size_t>(e)]; }
};

struct FrameInfo {
  MacAddress dst{};
  MacAddress src{};
  bool vlan = false;
  std::uint16_t vlan_tci = 0;
  std::uint16_t ecat_length = 0;
  std::uint8_t ecat_type = 0;
  std::size_t first_datagram_offset = 0;  // offset of the first datagram header in the frame
};

struct Datagram {
  DatagramHeader header{};
  std::span<const std::uint8_t> data{};
  std::uint16_t wkc = 0;
  std::size_t header_offset = 0;  // offsets in the frame, for a caller that rewrites in place
  std::size_t data_offset = 0;
  std::size_t wkc_offset = 0;
};

// Walks a received frame. The constructor checks the Ethernet and EtherCAT headers; next() yields
// the datagrams in order and stops at the end or at the first malformed one (error() says why).
// A frame is well-formed when next() returned false and error() is None.
class FrameParser {
 public:
  explicit FrameParser(std::span<const std::uint8_t> frame) noexcept;

  FrameError error() const noexcept { return error_; }
  const FrameInfo& info() const noexcept { return info_; }
  bool next(Datagram& out) noexcept;

 private:
  std::span<const std::uint8_t> frame_;
  FrameInfo info_{};
  FrameError error_ = FrameError::None;
  std::size_t pos_ = 0;
  std::size_t end_ = 0;  // end of the EtherCAT length
  bool done_ = false;
};

// Parses the whole frame; returns the first error (None when well-formed) and the datagram count.
FrameError validate_frame(std::span<const std::uint8_t> frame, std::size_t* datagrams = nullptr) noexcept;

}  // namespace drivegate::ethercat
