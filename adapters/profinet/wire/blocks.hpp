#pragma once
// PNIO connection management blocks, part 1: the block header, walking a list of blocks, and the
// Connect blocks that set up the AR and its communication relations [IEC 61158-6-10 §5.2.1
// "BlockHeader", §5.2.2 ARBlockReq/Res, IOCRBlockReq/Res, AlarmCRBlockReq/Res].
//
//   BlockHeader (6)  BlockType u16 | BlockLength u16 (bytes after this field, so it counts the
//                    two version octets) | BlockVersionHigh u8 | BlockVersionLow u8
//
// Blocks are always big-endian, whatever the RPC header's drep says. Encoders write into a
// caller's span and return the byte count (0 when the span is too small or a value does not fit);
// decoders take the span starting at the block header and return views into it. Every decoder
// checks the type, BlockVersionHigh 1, that BlockLength lies within the input, and that the fields
// end exactly where BlockLength says.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/rpc_cursor.hpp"

namespace drivegate::profinet {

inline constexpr std::size_t kBlockHeaderSize = 6;
inline constexpr std::uint16_t kEtherTypePnio = 0x8892;  // LT of IOCR and AlarmCR

// Block types [IEC 61158-6-10 Table "BlockType"]; a response is its request | 8000h.
namespace block_type {
inline constexpr std::uint16_t kWriteReqHeader = 0x0008;
inline constexpr std::uint16_t kReadReqHeader = 0x0009;
inline constexpr std::uint16_t kIm0 = 0x0020;
inline constexpr std::uint16_t kIm1 = 0x0021;
inline constexpr std::uint16_t kArBlockReq = 0x0101;
inline constexpr std::uint16_t kIocrBlockReq = 0x0102;
inline constexpr std::uint16_t kAlarmCrBlockReq = 0x0103;
inline constexpr std::uint16_t kExpectedSubmoduleBlockReq = 0x0104;
inline constexpr std::uint16_t kPrmEndReq = 0x0110;            // IODControlReq, Prm End
inline constexpr std::uint16_t kApplicationReadyReq = 0x0112;  // IOXControlReq, Application Ready
inline constexpr std::uint16_t kReleaseReq = 0x0114;
inline constexpr std::uint16_t kWriteResHeader = 0x8008;
inline constexpr std::uint16_t kReadResHeader = 0x8009;
inline constexpr std::uint16_t kArBlockRes = 0x8101;
inline constexpr std::uint16_t kIocrBlockRes = 0x8102;
inline constexpr std::uint16_t kAlarmCrBlockRes = 0x8103;
inline constexpr std::uint16_t kModuleDiffBlock = 0x8104;
inline constexpr std::uint16_t kPrmEndRes = 0x8110;
inline constexpr std::uint16_t kApplicationReadyRes = 0x8112;
inline constexpr std::uint16_t kReleaseRes = 0x8114;
}  // namespace block_type
std::string_view block_type_name(std::uint16_t type) noexcept;  // "ARBlockReq", ..., "unknown block"

struct BlockHeader {
  std::uint16_t type = 0;
  std::uint16_t length = 0;
  std::uint8_t version_high = 1;
  std::uint8_t version_low = 0;
  bool operator==(const BlockHeader&) const = default;
};

struct BlockView {
  WireError error = WireError::None;
  BlockHeader header{};
  std::span<const std::uint8_t> block{};  // the whole block: header and BlockLength - 2 more bytes
  std::span<const std::uint8_t> body{};   // after the version octets
};
// The block at the start of `in`: BlockLength >= 2 and within `in`.
BlockView decode_block(std::span<const std::uint8_t> in) noexcept;

// Walks the blocks of a PNIO request or response (the NDR args) one after the other.
class BlockWalker {
 public:
  explicit BlockWalker(std::span<const std::uint8_t> blocks) noexcept : rest_(blocks) {}
  // The next block; false at the end or on a malformed block (error() tells which).
  bool next(BlockView& out) noexcept;
  [[nodiscard]] WireError error() const noexcept { return error_; }

 private:
  std::span<const std::uint8_t> rest_;
  WireError error_ = WireError::None;
};

// Block writing helpers for encoders: begin writes the header with a zero length, end patches it.
std::size_t begin_block(Writer& w, std::uint16_t type, std::uint8_t version_low = 0) noexcept;
void end_block(Writer& w, std::size_t start) noexcept;

// ---- ARBlockReq 0101h / ARBlockRes 8101h [IEC 61158-6-10 §5.2.2.1] -----------------------------

namespace ar_type {
inline constexpr std::uint16_t kIocarSingle = 0x0001;
inline constexpr std::uint16_t kIosar = 0x0006;  // supervisor AR
}  // namespace ar_type
// ARProperties bits [IEC 61158-6-10 "ARProperties"].
namespace ar_properties {
inline constexpr std::uint32_t kStateActive = 0x00000001;                    // bits 0-2 = 1
inline constexpr std::uint32_t kSupervisorTakeoverAllowed = 0x00000008;      // bit 3
inline constexpr std::uint32_t kParametrizationServerCmInitiator = 0x00000010;  // bit 4
inline constexpr std::uint32_t kDeviceAccess = 0x00000100;                   // bit 8
inline constexpr std::uint32_t kStartupModeAdvanced = 0x40000000;            // bit 30
inline constexpr std::uint32_t kPullModuleAlarmAllowed = 0x80000000;         // bit 31
}  // namespace ar_properties
inline constexpr std::size_t kMaxStationNameLength = 240;  // NameOfStation [IEC 61158-6-10 §4.3.1.4.16]

struct ArBlockReq {
  std::uint16_t ar_type = ar_type::kIocarSingle;
  Uuid ar_uuid{};
  std::uint16_t session_key = 0;
  MacAddress initiator_mac{};
  Uuid initiator_object_uuid{};
  std::uint32_t properties = ar_properties::kStateActive | ar_properties::kParametrizationServerCmInitiator;
  std::uint16_t activity_timeout_factor = 100;  // × 100 ms
  std::uint16_t udp_rt_port = kEtherTypePnio;   // 8892h: RT over Ethernet, not UDP
  std::string_view station_name{};              // CMInitiatorStationName, 1..240 octets
};
std::size_t encode_ar_block_req(const ArBlockReq& b, std::span<std::uint8_t> out) noexcept;
struct ArBlockReqView {
  WireError error = WireError::None;
  ArBlockReq block{};  // station_name views the input
  std::size_t size = 0;
};
ArBlockReqView decode_ar_block_req(std::span<const std::uint8_t> in) noexcept;

struct ArBlockRes {
  std::uint16_t ar_type = ar_type::kIocarSingle;
  Uuid ar_uuid{};
  std::uint16_t session_key = 0;
  MacAddress responder_mac{};
  std::uint16_t responder_udp_rt_port = kEtherTypePnio;
  bool operator==(const ArBlockRes&) const = default;
};
inline constexpr std::size_t kArBlockResSize = 34;
std::size_t encode_ar_block_res(const ArBlockRes& b, std::span<std::uint8_t> out) noexcept;
struct ArBlockResView {
  WireError error = WireError::None;
  ArBlockRes block{};
  std::size_t size = 0;
};
ArBlockResView decode_ar_block_res(std::span<const std::uint8_t> in) noexcept;

// ---- IOCRBlockReq 0102h / IOCRBlockRes 8102h [IEC 61158-6-10 §5.2.2.2] ---------------------------

namespace iocr_type {
inline constexpr std::uint16_t kInput = 1;   // device -> controller
inline constexpr std::uint16_t kOutput = 2;  // controller -> device
}  // namespace iocr_type
// IOCRProperties bits 0-3 RTClass [IEC 61158-6-10 "IOCRProperties"]; the AKD speaks RT only
// (digest §2): class 1 frames.
namespace iocr_properties {
inline constexpr std::uint32_t kRtClass1 = 0x00000001;
inline constexpr std::uint32_t kRtClass2 = 0x00000002;
inline constexpr std::uint32_t kRtClass3 = 0x00000003;
inline constexpr std::uint32_t kRtClassUdp = 0x00000004;
}  // namespace iocr_properties

// One IO data object or IOCS entry: where a submodule's data or its consumer status sits in the frame.
struct IoObjectRef {
  std::uint16_t slot = 0;
  std::uint16_t subslot = 0;
  std::uint16_t frame_offset = 0;
  bool operator==(const IoObjectRef&) const = default;
};
struct IocrApiSpec {
  std::uint32_t api = 0;
  std::span<const IoObjectRef> data_objects{};
  std::span<const IoObjectRef> iocs{};
};
struct IocrParams {
  std::uint16_t type = iocr_type::kInput;
  std::uint16_t reference = 1;
  std::uint16_t lt = kEtherTypePnio;
  std::uint32_t properties = iocr_properties::kRtClass1;
  std::uint16_t data_length = 40;  // C_SDU length, 40..1440
  std::uint16_t frame_id = 0xFFFF;
  std::uint16_t send_clock_factor = 32;  // × 31.25 µs
  std::uint16_t reduction_ratio = 32;
  std::uint16_t phase = 1;
  std::uint16_t sequence = 0;
  std::uint32_t frame_send_offset = 0xFFFFFFFF;  // "best effort"
  std::uint16_t watchdog_factor = 3;
  std::uint16_t data_hold_factor = 3;
  std::uint16_t tag_header = 0xC000;  // VLAN priority 6, VLAN ID 0
  MacAddress multicast_mac{};
  bool operator==(const IocrParams&) const = default;
};
std::size_t encode_iocr_block_req(const IocrParams& p, std::span<const IocrApiSpec> apis,
                                  std::span<std::uint8_t> out) noexcept;

struct IocrBlockReqView {
  WireError error = WireError::None;
  IocrParams params{};
  std::uint16_t api_count = 0;
  std::span<const std::uint8_t> apis{};  // the API list, validated; walk it with IocrEntryReader
  std::size_t size = 0;
};
IocrBlockReqView decode_iocr_block_req(std::span<const std::uint8_t> in) noexcept;

// One entry of a decoded IOCR's API list, flat: an IO data object or an IOCS of an API.
struct IocrEntry {
  std::uint32_t api = 0;
  bool iocs = false;  // false: IO data object
  IoObjectRef ref{};
};
class IocrEntryReader {
 public:
  explicit IocrEntryReader(const IocrBlockReqView& v) noexcept
      : r_(v.apis, ByteOrder::Big), apis_left_(v.error == WireError::None ? v.api_count : 0) {}
  bool next(IocrEntry& out) noexcept;

 private:
  Reader r_;
  std::uint16_t apis_left_;
  std::uint16_t objects_left_ = 0;
  std::uint16_t iocs_left_ = 0;
  bool in_api_ = false;
  bool in_iocs_ = false;
  std::uint32_t api_ = 0;
};

struct IocrBlockRes {
  std::uint16_t type = iocr_type::kInput;
  std::uint16_t reference = 1;
  std::uint16_t frame_id = 0;
  bool operator==(const IocrBlockRes&) const = default;
};
inline constexpr std::size_t kIocrBlockResSize = 12;
std::size_t encode_iocr_block_res(const IocrBlockRes& b, std::span<std::uint8_t> out) noexcept;
struct IocrBlockResView {
  WireError error = WireError::None;
  IocrBlockRes block{};
  std::size_t size = 0;
};
IocrBlockResView decode_iocr_block_res(std::span<const std::uint8_t> in) noexcept;

// ---- AlarmCRBlockReq 0103h / AlarmCRBlockRes 8103h [IEC 61158-6-10 §5.2.2.3] ---------------------

struct AlarmCrBlockReq {
  std::uint16_t type = 1;  // AlarmCRType 1 = alarm CR
  std::uint16_t lt = kEtherTypePnio;
  std::uint32_t properties = 0;  // bit 0 priority (0 = user priority), bit 1 transport (0 = RTA_CLASS_1)
  std::uint16_t rta_timeout_factor = 1;  // × 100 ms
  std::uint16_t rta_retries = 3;         // 3..15
  std::uint16_t local_alarm_reference = 1;
  std::uint16_t max_alarm_data_length = 200;  // 200..1432
  std::uint16_t tag_header_high = 0xC000;     // VLAN priority 6
  std::uint16_t tag_header_low = 0xA000;      // VLAN priority 5
  bool operator==(const AlarmCrBlockReq&) const = default;
};
inline constexpr std::size_t kAlarmCrBlockReqSize = 26;
std::size_t encode_alarm_cr_block_req(const AlarmCrBlockReq& b, std::span<std::uint8_t> out) noexcept;
struct AlarmCrBlockReqView {
  WireError error = WireError::None;
  AlarmCrBlockReq block{};
  std::size_t size = 0;
};
AlarmCrBlockReqView decode_alarm_cr_block_req(std::span<const std::uint8_t> in) noexcept;

struct AlarmCrBlockRes {
  std::uint16_t type = 1;
  std::uint16_t local_alarm_reference = 1;
  std::uint16_t max_alarm_data_length = 200;
  bool operator==(const AlarmCrBlockRes&) const = default;
};
inline constexpr std::size_t kAlarmCrBlockResSize = 12;
std::size_t encode_alarm_cr_block_res(const AlarmCrBlockRes& b, std::span<std::uint8_t> out) noexcept;
struct AlarmCrBlockResView {
  WireError error = WireError::None;
  AlarmCrBlockRes block{};
  std::size_t size = 0;
};
AlarmCrBlockResView decode_alarm_cr_block_res(std::span<const std::uint8_t> in) noexcept;

// ---- shared by the block decoders ----------------------------------------------------------------

// Opens the block at the start of `in` for a decoder: checks type and version high 1 and returns a
// big-endian reader over the body; `body_min` is the fixed part's size (BlockLengthTooShort below).
struct BlockBody {
  WireError error = WireError::None;
  BlockHeader header{};
  std::span<const std::uint8_t> body{};
  std::size_t size = 0;  // the whole block
};
BlockBody open_block(std::span<const std::uint8_t> in, std::uint16_t type, std::size_t body_min) noexcept;
// The same for a block that may be one of several types (`types`).
BlockBody open_block_of(std::span<const std::uint8_t> in, std::span<const std::uint16_t> types,
                        std::size_t body_min) noexcept;
// The decoder's verdict: the reader's first error, else BlockLengthMismatch if bytes are left.
WireError finish_block(const Reader& r) noexcept;

}  // namespace drivegate::profinet
