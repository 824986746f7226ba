#pragma once
// Base mode parameter access over record index 47 [akd-profinet-profidrive.md §5]: the request
// encoder, the response decoder, the error-number texts and the check of a response against its
// request. Sans-I/O: the adapter writes the request with an RPC Write Record and fetches the
// response with Read Record (§5.1); this file only builds and reads the bytes. Nothing allocates:
// decoded blocks are views into the caller's buffer.
//
//   request   reference u8 | request ID u8 (01h read, 02h change) | axis u8 | n u8
//             n x (attribute u8 | elements u8 | PNU u16 | subindex u16)
//             change only: n x (format u8 | number of values u8 | values, big-endian [| pad])
//   response  reference u8 | response ID u8 (01h/02h positive, 81h/82h negative) | axis u8 | n u8
//             n x (format u8 | number of values u8 | values [| pad]); error blocks are format 44h
//             with 1 or 2 U16 (error number, additional information); a positive change response is
//             the header alone [STD] or, on the AKD, the header plus "00 00" (§5.3, §23.3).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace drivegate::profidrive {

inline constexpr std::uint16_t kParameterRecordIndex = 47;  // slot 1 [§5.1]
inline constexpr std::size_t kParamHeaderSize = 4;
inline constexpr std::size_t kParamAddressSize = 6;
inline constexpr std::size_t kMaxParameters = 39;  // 0x27 [§5.2]: 4 + 39 x 6 = 238 bytes
inline constexpr std::uint8_t kMaxElements = 234;  // 0xEA [§5.2]
inline constexpr std::uint16_t kMaxSubindex = 0xFFFE;
// [STD] A parameter request or response is at most 240 bytes (which is where the 39 above comes
// from); the encoder refuses longer requests, the decoder takes whatever the record holds.
inline constexpr std::size_t kMaxParamRecord = 240;

enum class RequestId : std::uint8_t { Read = 0x01, Change = 0x02 };

namespace response_id {
inline constexpr std::uint8_t kReadOk = 0x01;
inline constexpr std::uint8_t kChangeOk = 0x02;
inline constexpr std::uint8_t kReadFailed = 0x81;
inline constexpr std::uint8_t kChangeFailed = 0x82;
}  // namespace response_id

enum class Attribute : std::uint8_t { Value = 0x10, Description = 0x20, Text = 0x30 };

// Value-block formats [§5.2; STD for the typed ones, 40h and 44h].
namespace format {
inline constexpr std::uint8_t kAkdNone = 0x00;  // the AKD's positive change reply "00 00" [§5.3]
inline constexpr std::uint8_t kInteger8 = 0x02;
inline constexpr std::uint8_t kInteger16 = 0x03;
inline constexpr std::uint8_t kInteger32 = 0x04;
inline constexpr std::uint8_t kUnsigned8 = 0x05;
inline constexpr std::uint8_t kUnsigned16 = 0x06;
inline constexpr std::uint8_t kUnsigned32 = 0x07;
inline constexpr std::uint8_t kFloat32 = 0x08;
inline constexpr std::uint8_t kVisibleString = 0x09;
inline constexpr std::uint8_t kOctetString = 0x0A;
inline constexpr std::uint8_t kZero = 0x40;  // no values (change responses)
inline constexpr std::uint8_t kByte = 0x41;
inline constexpr std::uint8_t kWord = 0x42;
inline constexpr std::uint8_t kDWord = 0x43;
inline constexpr std::uint8_t kError = 0x44;
}  // namespace format
// Bytes per value of a format; 0 for 00h/40h (no values) and for unknown formats.
std::size_t format_size(std::uint8_t fmt) noexcept;
// A format that carries values (typed, 41h..43h) - not 00h, 40h, 44h or unknown.
bool is_value_format(std::uint8_t fmt) noexcept;

struct ParamAddress {
  Attribute attribute = Attribute::Value;
  std::uint8_t elements = 1;  // 1..234
  std::uint16_t pnu = 0;      // 1..65535
  std::uint16_t subindex = 0; // 0..65534
  bool operator==(const ParamAddress&) const = default;
};

struct ParamChange {
  ParamAddress address;
  std::uint8_t format = format::kWord;     // 41h, 42h or 43h: what the AKD accepts [§5.2, §11.3]
  std::span<const std::uint32_t> values;   // one per element; each must fit the format
};

enum class ParamError : std::uint8_t {
  None,
  // Encoding.
  BufferTooSmall,
  BadReference,       // 0 is reserved [§5.2]
  BadCount,           // 0 or more than 39 parameters
  BadElements,        // 0 or more than 234 elements
  BadPnu,             // PNU 0
  BadSubindex,        // FFFFh
  BadFormat,          // a change format other than 41h/42h/43h
  ValueCountMismatch, // number of values differs from the number of elements
  ValueTooWide,       // a value does not fit its format
  TooLong,            // the request would exceed 240 bytes
  // Decoding.
  Truncated,          // shorter than a header, an address or a block header
  UnknownId,          // request/response ID not 01h/02h (81h/82h)
  BadAttribute,
  UnknownFormat,
  CountBeyondData,    // a block's number of values runs past the end
  BadErrorBlock,      // format 44h with other than 1 or 2 values
  BadZeroBlock,       // format 00h/40h with values, or 00h outside a change response
  TrailingBytes,
  ErrorInPositive,    // an error block in a 01h/02h response
  NoErrorInNegative,  // an 81h/82h response without any error block
};
std::string_view to_string(ParamError e) noexcept;

struct EncodeResult {
  ParamError error = ParamError::None;
  std::size_t size = 0;   // bytes written
  std::size_t index = 0;  // the offending parameter
};

EncodeResult encode_read_request(std::span<std::uint8_t> out, std::uint8_t reference,
                                 std::span<const ParamAddress> params, std::uint8_t axis = 0) noexcept;
EncodeResult encode_change_request(std::span<std::uint8_t> out, std::uint8_t reference,
                                   std::span<const ParamChange> params, std::uint8_t axis = 0) noexcept;

// One value block, a view into the decoded buffer.
struct ValueBlock {
  std::uint8_t format = 0;
  std::uint8_t count = 0;
  std::span<const std::uint8_t> data;  // count x format_size(format) bytes, without the pad
  [[nodiscard]] bool is_error() const noexcept { return format == format::kError; }
  [[nodiscard]] bool is_empty() const noexcept { return format == format::kZero || format == format::kAkdNone; }
  // Element i as an unsigned big-endian number (i < count).
  [[nodiscard]] std::uint32_t value(std::size_t i) const noexcept;
  [[nodiscard]] std::uint16_t error_number() const noexcept { return is_error() ? static_cast<std::uint16_t>(value(0)) : 0; }
  // The second word of an error block (e.g. the subindex of the first faulty element) [STD].
  [[nodiscard]] std::optional<std::uint16_t> error_info() const noexcept;
};

struct ParamResponse {
  std::uint8_t reference = 0;
  std::uint8_t response_id = 0;
  std::uint8_t axis = 0;
  std::uint8_t count = 0;
  std::uint8_t block_count = 0;  // == count, or 0 for a header-only positive change response
  std::array<ValueBlock, kMaxParameters> blocks{};
  [[nodiscard]] bool positive() const noexcept { return (response_id & 0x80U) == 0; }
  [[nodiscard]] bool is_change() const noexcept { return (response_id & 0x7FU) == 0x02; }
  [[nodiscard]] std::span<const ValueBlock> values() const noexcept {
    return std::span<const ValueBlock>(blocks).first(block_count);
  }
};

struct ResponseResult {
  ParamError error = ParamError::None;
  std::size_t at = 0;  // byte offset where decoding stopped
  ParamResponse response;
};
ResponseResult decode_param_response(std::span<const std::uint8_t> in) noexcept;

// The drive's side (the simulator): a response with its header and `response.values()`, each
// block with `count` x format_size bytes of data (as the decoder returns them) and odd blocks padded
// to a word. An empty values() with 02h is the standard 4-byte change reply. Refuses unknown IDs and
// formats, blocks whose data does not match their count, and records over 240 bytes.
EncodeResult encode_param_response(std::span<std::uint8_t> out, const ParamResponse& response) noexcept;

// A request read back (the simulated drive's side, and the reference for check_response).
struct ParamRequest {
  std::uint8_t reference = 0;
  RequestId id = RequestId::Read;
  std::uint8_t axis = 0;
  std::uint8_t count = 0;
  std::array<ParamAddress, kMaxParameters> params{};
  std::array<ValueBlock, kMaxParameters> values{};  // change requests only
  [[nodiscard]] std::span<const ParamAddress> addresses() const noexcept {
    return std::span<const ParamAddress>(params).first(count);
  }
};
struct RequestResult {
  ParamError error = ParamError::None;
  std::size_t at = 0;
  ParamRequest request;
};
RequestResult decode_param_request(std::span<const std::uint8_t> in) noexcept;

// Whether a (well-formed) response answers this request.
enum class ParamMismatch : std::uint8_t {
  None,
  Reference,         // another request's answer (or a stale one)
  ResponseId,        // a read answered as a change or the other way round
  Axis,
  ParameterCount,
  ValueCount,        // a read value block with another number of values than elements requested
  Format,            // a read answered with no values (00h/40h)
  ValuesInChange,    // a change answered with values
};
std::string_view to_string(ParamMismatch m) noexcept;
struct CheckResult {
  ParamMismatch mismatch = ParamMismatch::None;
  std::size_t parameter = 0;  // the offending parameter for ValueCount/Format/ValuesInChange
};
CheckResult check_response(const ParamRequest& request, const ParamResponse& response) noexcept;

// The PROFIdrive parameter-access error numbers in words [§5.4; STD]. Numbers 65h..FFh are
// manufacturer-specific; the AKD documents none [§25.13].
std::string_view param_error_text(std::uint16_t error_number) noexcept;

}  // namespace drivegate::profidrive
