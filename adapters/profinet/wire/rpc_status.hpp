#pragma once
// PNIOStatus: the four octets every PNIO response, record response and RTA error carries
// [IEC 61158-6-10 §5.2.6 "Coding of the field PNIOStatus": ErrorCode, ErrorDecode, ErrorCode1,
// ErrorCode2], with texts a person can act on.
//
//   ErrorCode    00 OK, 81 PNIO, CF RTA error, DA AlarmAck, DB IODConnectRes, DC IODReleaseRes,
//                DD IODControlRes, DE IODReadRes, DF IODWriteRes
//   ErrorDecode  80 PNIORW (record services: ErrorCode1 = error class << 4 | error code,
//                ErrorCode2 user specific), 81 PNIO (ErrorCode1 names the faulty block or the
//                protocol machine, ErrorCode2 the parameter or the reason), 82 manufacturer specific
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::profinet {

struct PnioStatus {
  std::uint8_t code = 0;
  std::uint8_t decode = 0;
  std::uint8_t code1 = 0;
  std::uint8_t code2 = 0;
  [[nodiscard]] bool ok() const noexcept { return code == 0 && decode == 0 && code1 == 0 && code2 == 0; }
  bool operator==(const PnioStatus&) const = default;
};

// PNIOStatus as one Unsigned32, ErrorCode in bits 24-31 ... ErrorCode2 in bits 0-7: how the NDR
// part of a response carries it (in the drep byte order).
constexpr std::uint32_t status_to_u32(const PnioStatus& s) noexcept {
  return (std::uint32_t{s.code} << 24) | (std::uint32_t{s.decode} << 16) | (std::uint32_t{s.code1} << 8) | s.code2;
}
constexpr PnioStatus status_from_u32(std::uint32_t v) noexcept {
  return {static_cast<std::uint8_t>(v >> 24), static_cast<std::uint8_t>((v >> 16) & 0xFF),
          static_cast<std::uint8_t>((v >> 8) & 0xFF), static_cast<std::uint8_t>(v & 0xFF)};
}

namespace pnio_error_code {
inline constexpr std::uint8_t kOk = 0x00;
inline constexpr std::uint8_t kPnio = 0x81;
inline constexpr std::uint8_t kRtaError = 0xCF;
inline constexpr std::uint8_t kAlarmAck = 0xDA;
inline constexpr std::uint8_t kConnect = 0xDB;
inline constexpr std::uint8_t kRelease = 0xDC;
inline constexpr std::uint8_t kControl = 0xDD;
inline constexpr std::uint8_t kRead = 0xDE;
inline constexpr std::uint8_t kWrite = 0xDF;
}  // namespace pnio_error_code
namespace pnio_error_decode {
inline constexpr std::uint8_t kPniorw = 0x80;
inline constexpr std::uint8_t kPnio = 0x81;
inline constexpr std::uint8_t kManufacturer = 0x82;
}  // namespace pnio_error_decode
// A few ErrorCode1 values of ErrorDecode PNIO [IEC 61158-6-10 Table "Values of ErrorCode1 for
// ErrorDecode PNIO"].
namespace pnio_error_code1 {
inline constexpr std::uint8_t kArBlockReq = 1;
inline constexpr std::uint8_t kIocrBlockReq = 2;
inline constexpr std::uint8_t kExpectedSubmoduleBlockReq = 3;
inline constexpr std::uint8_t kAlarmCrBlockReq = 4;
inline constexpr std::uint8_t kRecord = 8;
inline constexpr std::uint8_t kControlBlockConnect = 20;
inline constexpr std::uint8_t kReleaseBlock = 40;
inline constexpr std::uint8_t kCmdev = 61;
inline constexpr std::uint8_t kCmctl = 62;
inline constexpr std::uint8_t kCmrpc = 64;
inline constexpr std::uint8_t kRtaProtocol = 253;
}  // namespace pnio_error_code1
// PNIORW ErrorCode1 = class << 4 | code [IEC 61158-6-10 Table "Values of ErrorCode1 for ErrorDecode
// PNIORW"]: the ones a record client meets.
namespace pniorw_error {
inline constexpr std::uint8_t kReadError = 0xA0;
inline constexpr std::uint8_t kWriteError = 0xA1;
inline constexpr std::uint8_t kBusy = 0xA7;
inline constexpr std::uint8_t kInvalidIndex = 0xB0;
inline constexpr std::uint8_t kWriteLengthError = 0xB1;
inline constexpr std::uint8_t kInvalidSlot = 0xB2;
inline constexpr std::uint8_t kStateConflict = 0xB5;
inline constexpr std::uint8_t kAccessDenied = 0xB6;
inline constexpr std::uint8_t kInvalidRange = 0xB7;
inline constexpr std::uint8_t kResourceBusy = 0xC2;
inline constexpr std::uint8_t kResourceUnavailable = 0xC3;
}  // namespace pniorw_error

std::string_view error_code_text(std::uint8_t code) noexcept;      // "IODConnectRes", ...
std::string_view error_decode_text(std::uint8_t decode) noexcept;  // "PNIORW", "PNIO", ...
// ErrorCode1 in the context of ErrorDecode: "Connect: Faulty ARBlockReq", "access: invalid index",
// or "" when unknown.
std::string_view error_code1_text(std::uint8_t decode, std::uint8_t code1) noexcept;
// ErrorCode2 in the context of ErrorDecode PNIO and ErrorCode1: "Error in Parameter ARType",
// "AR UUID unknown", or "" when unknown (PNIORW ErrorCode2 is user specific: always "").
std::string_view error_code2_text(std::uint8_t decode, std::uint8_t code1, std::uint8_t code2) noexcept;

// One line for a person, written into `out` (truncated to fit; no allocation), e.g.
// "IODConnectRes PNIO: Connect: Faulty ARBlockReq: Error in Parameter ARType (DB 81 01 04)"
// or "OK". Returns a view of what was written.
std::string_view describe(const PnioStatus& s, std::span<char> out) noexcept;

}  // namespace drivegate::profinet
