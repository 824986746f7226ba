#include "adapters/ethercat/wire/frame.hpp"

#include <algorithm>

#include "core/bytes.hpp"

namespace drivegate::ethercat {

using core::get_u16;
using core::get_u32;
using core::put_u16;
using core::put_u32;

namespace {

struct CommandInfo {
  std::string_view name;
  std::string_view description;
  Addressing addressing;
  Access access;
};

// [ETG.1000.4 §5.4]
constexpr std::array<CommandInfo, kCommandCount> kCommands{{
    {"NOP", "no operation", Addressing::None, Access::None},
    {"APRD", "auto increment physical read", Addressing::AutoIncrement, Access::Read},
    {"APWR", "auto increment physical write", Addressing::AutoIncrement, Access::Write},
    {"APRW", "auto increment physical read write", Addressing::AutoIncrement, Access::ReadWrite},
    {"FPRD", "configured address physical read", Addressing::Configured, Access::Read},
    {"FPWR", "configured address physical write", Addressing::Configured, Access::Write},
    {"FPRW", "configured address physical read write", Addressing::Configured, Access::ReadWrite},
    {"BRD", "broadcast read", Addressing::Broadcast, Access::Read},
    {"BWR", "broadcast write", Addressing::Broadcast, Access::Write},
    {"BRW", "broadcast read write", Addressing::Broadcast, Access::ReadWrite},
    {"LRD", "logical memory read", Addressing::Logical, Access::Read},
    {"LWR", "logical memory write", Addressing::Logical, Access::Write},
    {"LRW", "logical memory read write", Addressing::Logical, Access::ReadWrite},
    {"ARMW", "auto increment physical read multiple write", Addressing::AutoIncrement, Access::ReadMultipleWrite},
    {"FRMW", "configured address physical read multiple write", Addressing::Configured, Access::ReadMultipleWrite},
}};

const CommandInfo* info_of(Command c) noexcept {
  const auto i = static_cast<std::size_t>(c);
  return i < kCommands.size() ? &kCommands[i] : nullptr;
}

constexpr std::uint16_t kLengthMask = 0x07FF;
constexpr std::uint16_t kCirculatingBit = 0x4000;
constexpr std::uint16_t kMoreBit = 0x8000;

std::uint16_t clamp16(std::uint32_t v) noexcept { return static_cast<std::uint16_t>(std::min<std::uint32_t>(v, 0xFFFF)); }

}  // namespace

std::string_view command_name(Command c) noexcept {
  const auto* i = info_of(c);
  return i ? i->name : "?";
}

std::string_view command_description(Command c) noexcept {
  const auto* i = info_of(c);
  return i ? i->description : "unknown command";
}

Addressing addressing_of(Command c) noexcept {
  const auto* i = info_of(c);
  return i ? i->addressing : Addressing::None;
}

Access access_of(Command c) noexcept {
  const auto* i = info_of(c);
  return i ? i->access : Access::None;
}

std::uint16_t expected_wkc(Command c, std::uint16_t slaves) noexcept {
  switch (access_of(c)) {
    case Access::None: return 0;
    case Access::Read:
    case Access::Write:
    case Access::ReadMultipleWrite: return slaves;
    case Access::ReadWrite: return clamp16(3U * slaves);
  }
  return 0;
}

std::uint16_t expected_logical_wkc(Command c, std::uint16_t readers, std::uint16_t writers) noexcept {
  switch (c) {
    case Command::LRD: return readers;
    case Command::LWR: return writers;
    case Command::LRW: return clamp16(readers + 2U * writers);
    default: return 0;
  }
}

bool encode_datagram_header(const DatagramHeader& h, std::span<std::uint8_t> out) noexcept {
  if (out.size() < kDatagramHeaderSize || h.length > kLengthMask) return false;
  out[0] = static_cast<std::uint8_t>(h.command);
  out[1] = h.index;
  put_u32(out, 2, h.address);
  std::uint16_t len = h.length;
  if (h.circulating) len = static_cast<std::uint16_t>(len | kCirculatingBit);
  if (h.more) len = static_cast<std::uint16_t>(len | kMoreBit);
  put_u16(out, 6, len);
  put_u16(out, 8, h.irq);
  return true;
}

bool decode_datagram_header(std::span<const std::uint8_t> in, DatagramHeader& h) noexcept {
  if (in.size() < kDatagramHeaderSize) return false;
  h.command = static_cast<Command>(in[0]);
  h.index = in[1];
  h.address = get_u32(in, 2);
  const std::uint16_t len = get_u16(in, 6);
  h.length = static_cast<std::uint16_t>(len & kLengthMask);
  h.circulating = (len & kCirculatingBit) != 0;
  h.more = (len & kMoreBit) != 0;
  h.irq = get_u16(in, 8);
  return true;
}

// ---- Builder ----------------------------------------------------------------------------------

std::string_view to_string(BuildError e) noexcept {
  switch (e) {
    case BuildError::None: return "no error";
    case BuildError::BufferTooSmall: return "buffer smaller than a minimum Ethernet frame (60 bytes)";
    case BuildError::FrameFull: return "datagram does not fit in the frame (1514 bytes or the buffer)";
    case BuildError::DataTooLong: return "datagram data longer than its length, or length beyond 2047 bytes";
    case BuildError::Finished: return "frame already finished";
  }
  return "?";
}

FrameBuilder::FrameBuilder(std::span<std::uint8_t> buffer, const MacAddress& dst, const MacAddress& src) noexcept
    : buf_(buffer.first(std::min(buffer.size(), kMaxFrameSize))) {
  if (buf_.size() < kMinFrameSize) {
    state_error_ = BuildError::BufferTooSmall;
    return;
  }
  std::copy(dst.begin(), dst.end(), buf_.begin());
  std::copy(src.begin(), src.end(), buf_.begin() + 6);
  core::put_be16(buf_, kEtherTypeOffset, kEtherType);
  put_u16(buf_, kEthernetHeaderSize, 0);
  pos_ = kEthernetHeaderSize + kEcatHeaderSize;
}

std::size_t FrameBuilder::room() const noexcept {
  if (state_error_ != BuildError::None || finished_) return 0;
  // The EtherCAT length field (11 bits) also bounds what one frame can carry.
  const std::size_t ecat_used = pos_ - kEthernetHeaderSize - kEcatHeaderSize;
  return std::min(buf_.size() - pos_, kMaxEcatLength - ecat_used);
}

std::size_t FrameBuilder::remaining_data() const noexcept {
  const std::size_t r = room();
  return r >= kDatagramOverhead ? r - kDatagramOverhead : 0;
}

AddResult FrameBuilder::add(Command command, std::uint8_t index, std::uint32_t address, std::uint16_t length,
                            std::span<const std::uint8_t> data, std::uint16_t irq, std::uint16_t wkc) noexcept {
  if (state_error_ != BuildError::None) return {state_error_, {}};
  if (finished_) return {BuildError::Finished, {}};
  if (length > kLengthMask || data.size() > length) return {BuildError::DataTooLong, {}};
  if (room() < kDatagramOverhead + length) return {BuildError::FrameFull, {}};
  if (count_ > 0) {  // the previous datagram now has a successor: set its M bit
    const std::size_t at = last_header_ + 6;
    put_u16(buf_, at, static_cast<std::uint16_t>(get_u16(buf_, at) | kMoreBit));
  }
  DatagramHeader h;
  h.command = command;
  h.index = index;
  h.address = address;
  h.length = length;
  h.irq = irq;
  encode_datagram_header(h, buf_.subspan(pos_, kDatagramHeaderSize));
  DatagramSlot slot;
  slot.header_offset = pos_;
  slot.data_offset = pos_ + kDatagramHeaderSize;
  slot.wkc_offset = slot.data_offset + length;
  slot.length = length;
  std::copy(data.begin(), data.end(), buf_.begin() + static_cast<std::ptrdiff_t>(slot.data_offset));
  std::fill(buf_.begin() + static_cast<std::ptrdiff_t>(slot.data_offset + data.size()),
            buf_.begin() + static_cast<std::ptrdiff_t>(slot.wkc_offset), std::uint8_t{0});
  put_u16(buf_, slot.wkc_offset, wkc);
  last_header_ = pos_;
  pos_ = slot.wkc_offset + kWkcSize;
  ++count_;
  return {BuildError::None, slot};
}

std::span<std::uint8_t> FrameBuilder::finish() noexcept {
  if (state_error_ != BuildError::None || count_ == 0) return {};
  if (!finished_) {
    const auto ecat_len = static_cast<std::uint16_t>(pos_ - kEthernetHeaderSize - kEcatHeaderSize);
    // Type 1 in bits 12-15, length in bits 0-10 [ETG.1000.4 §5.3].
    put_u16(buf_, kEthernetHeaderSize, static_cast<std::uint16_t>(ecat_len | (kEcatTypeCommands << 12)));
    if (pos_ < kMinFrameSize) {
      std::fill(buf_.begin() + static_cast<std::ptrdiff_t>(pos_), buf_.begin() + kMinFrameSize, std::uint8_t{0});
      pos_ = kMinFrameSize;
    }
    finished_ = true;
  }
  return buf_.first(pos_);
}

// ---- Parser -----------------------------------------------------------------------------------

std::string_view to_string(FrameError e) noexcept {
  switch (e) {
    case FrameError::None: return "no error";
    case FrameError::TruncatedEthernet: return "frame shorter than its Ethernet header";
    case FrameError::WrongEtherType: return "EtherType is not 88A4h (EtherCAT)";
    case FrameError::TruncatedEcatHeader: return "frame ends before the EtherCAT header";
    case FrameError::UnsupportedType: return "EtherCAT header type is not 1 (EtherCAT commands)";
    case FrameError::EcatLengthBeyondFrame: return "EtherCAT length runs past the end of the frame";
    case FrameError::EmptyFrame: return "EtherCAT length 0: no datagram";
    case FrameError::TruncatedDatagramHeader: return "datagram header cut off by the EtherCAT length";
    case FrameError::DatagramBeyondLength: return "datagram data and working counter run past the EtherCAT length";
    case FrameError::UnknownCommand: return "unknown datagram command";
    case FrameError::MoreBitWithoutDatagram: return "M bit set on the last datagram of the frame";
    case FrameError::LengthAfterLastDatagram: return "bytes left in the EtherCAT length after the datagram without M bit";
  }
  return "?";
}

FrameParser::FrameParser(std::span<const std::uint8_t> frame) noexcept : frame_(frame) {
  auto fail = [this](FrameError e) {
    error_ = e;
    done_ = true;
  };
  if (frame_.size() < kEthernetHeaderSize) {
    fail(FrameError::TruncatedEthernet);
    return;
  }
  std::copy(frame_.begin(), frame_.begin() + 6, info_.dst.begin());
  std::copy(frame_.begin() + 6, frame_.begin() + 12, info_.src.begin());
  std::size_t at = kEtherTypeOffset;
  std::uint16_t type = core::get_be16(frame_, at);
  if (type == kVlanTpid) {
    if (frame_.size() < kEthernetHeaderSize + kVlanTagSize) {
      fail(FrameError::TruncatedEthernet);
      return;
    }
    info_.vlan = true;
    info_.vlan_tci = core::get_be16(frame_, at + 2);
    at += kVlanTagSize;
    type = core::get_be16(frame_, at);
  }
  if (type != kEtherType) {
    fail(FrameError::WrongEtherType);
    return;
  }
  at += 2;
  if (frame_.size() < at + kEcatHeaderSize) {
    fail(FrameError::TruncatedEcatHeader);
    return;
  }
  const std::uint16_t ecat = get_u16(frame_, at);
  info_.ecat_length = static_cast<std::uint16_t>(ecat & kLengthMask);
  info_.ecat_type = static_cast<std::uint8_t>(ecat >> 12);
  at += kEcatHeaderSize;
  info_.first_datagram_offset = at;
  if (info_.ecat_type != kEcatTypeCommands) {
    fail(FrameError::UnsupportedType);
    return;
  }
  if (info_.ecat_length > frame_.size() - at) {
    fail(FrameError::EcatLengthBeyondFrame);
    return;
  }
  if (info_.ecat_length == 0) {
    fail(FrameError::EmptyFrame);
    return;
  }
  pos_ = at;
  end_ = at + info_.ecat_length;
}

bool FrameParser::next(Datagram& out) noexcept {
  if (done_) return false;
  auto fail = [this](FrameError e) {
    error_ = e;
    done_ = true;
    return false;
  };
  if (end_ - pos_ < kDatagramHeaderSize) return fail(FrameError::TruncatedDatagramHeader);
  DatagramHeader h;
  decode_datagram_header(frame_.subspan(pos_, kDatagramHeaderSize), h);
  if (!is_valid_command(static_cast<std::uint8_t>(h.command))) return fail(FrameError::UnknownCommand);
  const std::size_t data_at = pos_ + kDatagramHeaderSize;
  if (end_ - data_at < static_cast<std::size_t>(h.length) + kWkcSize) return fail(FrameError::DatagramBeyondLength);
  const std::size_t wkc_at = data_at + h.length;
  const std::size_t after = wkc_at + kWkcSize;
  if (h.more && after == end_) return fail(FrameError::MoreBitWithoutDatagram);
  if (!h.more && after != end_) return fail(FrameError::LengthAfterLastDatagram);
  out.header = h;
  out.data = frame_.subspan(data_at, h.length);
  out.wkc = get_u16(frame_, wkc_at);
  out.header_offset = pos_;
  out.data_offset = data_at;
  out.wkc_offset = wkc_at;
  pos_ = after;
  if (!h.more) done_ = true;
  return true;
}

FrameError validate_frame(std::span<const std::uint8_t> frame, std::size_t* datagrams) noexcept {
  FrameParser p(frame);
  Datagram d;
  std::size_t n = 0;
  while (p.next(d)) ++n;
  if (datagrams) *datagrams = n;
  return p.error();
}

}  // namespace drivegate::ethercat
