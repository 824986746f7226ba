#pragma once
// Connectionless DCE/RPC as PROFINET IO uses it for connection management: UDP port 34964
// [IEC 61158-6-10 §4.10.3 "RPC", DCE 1.1 RPC ch. 12 "Connectionless RPC PDUs"].
//
//   RPC header (80)  rpc_vers u8 = 4 | ptype u8 | flags1 u8 | flags2 u8 | drep[3] | serial_hi u8 |
//                    object UUID | interface UUID | activity UUID | server_boot u32 |
//                    interface version u32 | seqnum u32 | opnum u16 | interface hint u16 |
//                    activity hint u16 | fragment length u16 | fragment number u16 |
//                    auth protocol u8 | serial_lo u8                    [DCE 1.1 RPC §12.5.1]
//   NDR request (20) ArgsMaximum u32 | ArgsLength u32 | MaximumCount u32 | Offset u32 |
//                    ActualCount u32, then ArgsLength bytes of PNIO blocks
//   NDR response(20) PNIOStatus (u32) | ArgsLength | MaximumCount | Offset | ActualCount
//                                                        [IEC 61158-6-10 §5.1.2 "IODConnectReq"...]
//
// The numbers of the RPC header and the NDR part are in the byte order drep names; the UUIDs'
// first three fields too (rpc_cursor.hpp). Encoders write into a caller's span and return the byte
// count, 0 when the span is too small or a value does not fit; decoders return views into the input.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/rpc_cursor.hpp"
#include "adapters/profinet/wire/rpc_status.hpp"

namespace drivegate::profinet {

inline constexpr std::uint16_t kRpcUdpPort = 34964;  // 0x8894 [IEC 61158-6-10 §4.10.3.2]
inline constexpr std::size_t kRpcHeaderSize = 80;
inline constexpr std::size_t kNdrHeaderSize = 20;
inline constexpr std::size_t kPnioBlocksOffset = kRpcHeaderSize + kNdrHeaderSize;  // where blocks start
inline constexpr std::uint8_t kRpcVersion = 4;

// [DCE 1.1 RPC §12.5.2.3] packet types of the connectionless protocol.
enum class PacketType : std::uint8_t {
  Request = 0,
  Ping = 1,
  Response = 2,
  Fault = 3,
  Working = 4,
  Nocall = 5,
  Reject = 6,
  Ack = 7,
  ClCancel = 8,
  Fack = 9,
  CancelAck = 10,
};
std::string_view to_string(PacketType t) noexcept;

// flags1 and flags2 [DCE 1.1 RPC §12.5.3.1/2].
namespace rpc_flag1 {
inline constexpr std::uint8_t kLastFragment = 0x02;
inline constexpr std::uint8_t kFragment = 0x04;
inline constexpr std::uint8_t kNoFack = 0x08;
inline constexpr std::uint8_t kMaybe = 0x10;
inline constexpr std::uint8_t kIdempotent = 0x20;
inline constexpr std::uint8_t kBroadcast = 0x40;
}  // namespace rpc_flag1
namespace rpc_flag2 {
inline constexpr std::uint8_t kCancelPending = 0x02;
}

// PNIO operations [IEC 61158-6-10 §4.10.3.2.2, Table "RPC operation numbers"].
enum class Opnum : std::uint16_t {
  Connect = 0,
  Release = 1,
  Read = 2,
  Write = 3,
  Control = 4,
  ReadImplicit = 5,
};
std::string_view to_string(Opnum o) noexcept;

// The PNIO interface UUIDs [IEC 61158-6-10 §4.10.3.2.1]; version 1.0 (interface version field = 1).
inline constexpr Uuid kPnioDeviceInterface{0xDEA00001, 0x6C97, 0x11D1, {0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF, 0x7D}};
inline constexpr Uuid kPnioControllerInterface{0xDEA00002, 0x6C97, 0x11D1,
                                              {0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF, 0x7D}};
inline constexpr Uuid kPnioSupervisorInterface{0xDEA00003, 0x6C97, 0x11D1,
                                              {0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF, 0x7D}};
inline constexpr std::uint32_t kPnioInterfaceVersion = 1;

// The PNIO object UUID DEA00000-6C97-11D1-8271-{instance u16}{device ID u16}{vendor ID u16}: the
// node part names the addressed device [IEC 61158-6-10 §4.10.3.2.1 "Object UUID"].
struct PnioObject {
  std::uint16_t instance = 1;
  std::uint16_t device_id = 0;
  std::uint16_t vendor_id = 0;
  bool operator==(const PnioObject&) const = default;
};
Uuid make_pnio_object_uuid(const PnioObject& o) noexcept;
// false when `u` is not of the DEA00000-6C97-11D1-8271 form.
bool parse_pnio_object_uuid(const Uuid& u, PnioObject& out) noexcept;

struct RpcHeader {
  std::uint8_t version = kRpcVersion;
  std::uint8_t packet_type = 0;  // PacketType value, raw
  std::uint8_t flags1 = 0;
  std::uint8_t flags2 = 0;
  ByteOrder order = ByteOrder::Little;  // drep[0] bits 4-7: 0 = big, 1 = little endian
  std::uint8_t drep_char = 0;           // drep[0] bits 0-3: 0 = ASCII (the only one accepted)
  std::uint8_t drep_float = 0;          // drep[1]: 0 = IEEE
  std::uint8_t serial_high = 0;
  Uuid object{};
  Uuid interface{};
  Uuid activity{};
  std::uint32_t server_boot_time = 0;
  std::uint32_t interface_version = kPnioInterfaceVersion;
  std::uint32_t sequence_number = 0;
  std::uint16_t opnum = 0;
  std::uint16_t interface_hint = 0xFFFF;  // 0xFFFF = no hint [DCE 1.1 RPC §12.5.3.8]
  std::uint16_t activity_hint = 0xFFFF;
  std::uint16_t fragment_length = 0;  // body bytes after the header
  std::uint16_t fragment_number = 0;
  std::uint8_t auth_protocol = 0;
  std::uint8_t serial_low = 0;
  bool operator==(const RpcHeader&) const = default;
};

// Writes the 80-byte header as given (fragment_length included); 0 when `out` is too small or
// drep_char is not ASCII.
std::size_t encode_rpc_header(const RpcHeader& h, std::span<std::uint8_t> out) noexcept;

struct RpcView {
  WireError error = WireError::None;
  RpcHeader header{};
  std::span<const std::uint8_t> body{};  // fragment_length bytes after the header
};
// A whole UDP payload. Bytes after the fragment are ignored (the body is exactly the fragment).
RpcView decode_rpc(std::span<const std::uint8_t> in) noexcept;

// ---- NDR wrapper of the PNIO operations [IEC 61158-6-10 §5.1.2, IDL of the PNIO interface] ----

struct NdrRequest {
  std::uint32_t args_maximum = 0;  // the largest response the caller takes (NDR conformant array)
  std::uint32_t args_length = 0;
  std::uint32_t maximum_count = 0;
  std::uint32_t offset = 0;
  std::uint32_t actual_count = 0;
  std::span<const std::uint8_t> blocks{};  // args_length bytes
};
struct NdrRequestView {
  WireError error = WireError::None;
  NdrRequest ndr{};
};
// `body` is an RPC request body; `order` the header's drep. Checks ArgsLength against the data
// and ActualCount == ArgsLength, Offset + ActualCount <= MaximumCount.
NdrRequestView decode_ndr_request(std::span<const std::uint8_t> body, ByteOrder order) noexcept;

struct NdrResponse {
  PnioStatus status{};
  std::uint32_t args_length = 0;
  std::uint32_t maximum_count = 0;
  std::uint32_t offset = 0;
  std::uint32_t actual_count = 0;
  std::span<const std::uint8_t> blocks{};
};
struct NdrResponseView {
  WireError error = WireError::None;
  NdrResponse ndr{};
};
NdrResponseView decode_ndr_response(std::span<const std::uint8_t> body, ByteOrder order) noexcept;

// The request composes in place: encode the blocks into pnio_blocks_area(out), then finish with
// their length. The header's fragment_length is set here; the NDR counts are ArgsMaximum =
// MaximumCount = args_maximum, ArgsLength = ActualCount = blocks_length, Offset 0.
inline std::span<std::uint8_t> pnio_blocks_area(std::span<std::uint8_t> out) noexcept {
  return out.size() < kPnioBlocksOffset ? std::span<std::uint8_t>{} : out.subspan(kPnioBlocksOffset);
}
std::size_t finish_pnio_request(RpcHeader h, std::uint32_t args_maximum, std::size_t blocks_length,
                                std::span<std::uint8_t> out) noexcept;
// Response: MaximumCount = the request's ArgsMaximum (`maximum_count`), ArgsLength = ActualCount
// = blocks_length.
std::size_t finish_pnio_response(RpcHeader h, const PnioStatus& status, std::uint32_t maximum_count,
                                 std::size_t blocks_length, std::span<std::uint8_t> out) noexcept;

// The header of the response to `request`: same object, interface, activity, sequence number,
// opnum and byte order, packet type Response, flags "last fragment, no fack", hints 0xFFFF.
RpcHeader response_header_for(const RpcHeader& request, std::uint32_t server_boot_time) noexcept;

// ---- Fault and reject [DCE 1.1 RPC §12.5.3.4, Appendix E] --------------------------------------

// The body of a fault/reject PDU is one status code (drep order).
struct RpcFaultView {
  WireError error = WireError::None;
  std::uint32_t status = 0;
};
RpcFaultView decode_rpc_fault(std::span<const std::uint8_t> body, ByteOrder order) noexcept;
// A fault or reject answering the call `h` names (response_header_for(request) gives it): the
// header with `type` and fragment length 4, then `status` in drep order. 0 when `type` is neither.
std::size_t encode_rpc_fault(RpcHeader h, PacketType type, std::uint32_t status, std::span<std::uint8_t> out) noexcept;
std::string_view nca_status_text(std::uint32_t status) noexcept;
namespace nca_status {
inline constexpr std::uint32_t kOpRangeError = 0x1C010002;
inline constexpr std::uint32_t kUnknownInterface = 0x1C010003;
inline constexpr std::uint32_t kProtoError = 0x1C01000B;
}  // namespace nca_status

}  // namespace drivegate::profinet
