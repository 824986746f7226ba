#pragma once
// Mailbox and CoE codecs [ETG.1000.6: the mailbox header (listed with the CoE elements, Table 29)
// and the mailbox error reply; §5.6 CoE: header, SDO, emergency, SDO information].
//
//   mailbox header (6)   length u16 (bytes after the header) | address u16 | channel bits 0-5,
//                        priority bits 6-7 | type bits 0-3, counter bits 4-6 (1..7, 0 = unused)
//   CoE header (2)       u16: number bits 0-8, service bits 12-15
//   SDO (8+)             command byte, index u16, subindex u8, 4 data bytes (CiA 301 layout),
//                        then for normal transfers the rest of the data up to the mailbox length
//
// Encoders write into a caller's span and return the byte count (0 when the span is too small or
// an argument is invalid). Decoders take the bytes read from SM1 (the whole mailbox buffer may be
// passed: only `length` bytes after the header count) and return views into them.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "core/bytes.hpp"

namespace drivegate::ethercat {

inline constexpr std::size_t kMailboxHeaderSize = 6;
inline constexpr std::size_t kCoeHeaderSize = 2;
inline constexpr std::size_t kSdoHeaderSize = 8;   // command, index, subindex, 4 data/size bytes
// Minimum CoE SDO mailbox length: CoE header + 8 SDO bytes (digest TV-6: "Mailbox length = 0x000A").
inline constexpr std::uint16_t kSdoMinMailboxLength = 10;
inline constexpr std::size_t kSdoSegmentMinData = 7;

// Mailbox types [ETG.1000.6 mailbox header, type field].
enum class MailboxType : std::uint8_t {
  Error = 0,
  AoE = 1,
  EoE = 2,
  CoE = 3,
  FoE = 4,
  SoE = 5,
  VoE = 15,
};
std::string_view to_string(MailboxType t) noexcept;  // "ERR", "AoE", ..., "unknown"

struct MailboxHeader {
  std::uint16_t length = 0;
  std::uint16_t address = 0;
  std::uint8_t channel = 0;   // 0..63
  std::uint8_t priority = 0;  // 0..3
  std::uint8_t type = 0;      // MailboxType value, raw (0..15)
  std::uint8_t counter = 0;   // 0..7
  bool operator==(const MailboxHeader&) const = default;
};

// Counter of the next new message: 1..7, wrapping 7 -> 1, never 0 [ETG.1000.6 mailbox header: 0 is
// reserved; a slave repeats the answer to a request whose counter did not change].
constexpr std::uint8_t next_mailbox_counter(std::uint8_t previous) noexcept {
  return static_cast<std::uint8_t>(previous >= 7 ? 1 : previous + 1);
}

bool encode_mailbox_header(const MailboxHeader& h, std::span<std::uint8_t> out) noexcept;

enum class MailboxError : std::uint8_t {
  None,
  TruncatedHeader,        // fewer than 6 bytes
  LengthBeyondBuffer,     // header length larger than the bytes after the header
  WrongType,              // not the mailbox type the decoder expects (e.g. not CoE)
  TruncatedCoeHeader,     // CoE: length < 2
  UnexpectedService,      // CoE service not the one(s) the decoder handles
  TruncatedSdo,           // SDO: fewer than 8 bytes after the CoE header
  UnknownSdoCommand,      // command specifier not valid for the direction
  SizeMismatch,           // normal initiate: more data than the complete size it indicates
  TruncatedEmergency,     // emergency: fewer than 8 bytes after the CoE header
  TruncatedSdoInfo,       // SDO information: header or fixed fields cut off
  UnknownSdoInfoOpcode,
  TruncatedMailboxError,  // mailbox error reply: fewer than 4 bytes
};
std::string_view to_string(MailboxError e) noexcept;

struct MailboxView {
  MailboxError error = MailboxError::None;
  MailboxHeader header{};
  std::span<const std::uint8_t> payload{};  // `length` bytes after the header
};
MailboxView decode_mailbox(std::span<const std::uint8_t> in) noexcept;

// ---- Mailbox error reply (type 0) [ETG.1000.6 mailbox error reply] -----------------------------------------

namespace mailbox_error_code {
inline constexpr std::uint16_t kSyntax = 0x0001;
inline constexpr std::uint16_t kUnsupportedProtocol = 0x0002;
inline constexpr std::uint16_t kInvalidChannel = 0x0003;
inline constexpr std::uint16_t kServiceNotSupported = 0x0004;
inline constexpr std::uint16_t kInvalidHeader = 0x0005;
inline constexpr std::uint16_t kSizeTooShort = 0x0006;
inline constexpr std::uint16_t kNoMoreMemory = 0x0007;
inline constexpr std::uint16_t kInvalidSize = 0x0008;
inline constexpr std::uint16_t kServiceInWork = 0x0009;
}  // namespace mailbox_error_code
std::string_view mailbox_error_text(std::uint16_t detail) noexcept;

struct MailboxErrorReply {
  MailboxError error = MailboxError::None;
  std::uint16_t type = 0;    // 0001h = mailbox command
  std::uint16_t detail = 0;  // mailbox_error_code
};
// Decodes a whole mailbox of type 0.
MailboxErrorReply decode_mailbox_error(std::span<const std::uint8_t> in) noexcept;
std::size_t encode_mailbox_error(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t detail) noexcept;

// ---- CoE header [ETG.1000.6 §5.6.1 Table 29] -------------------------------------------------------------

enum class CoeService : std::uint8_t {
  Emergency = 1,
  SdoRequest = 2,
  SdoResponse = 3,
  TxPdo = 4,
  RxPdo = 5,
  TxPdoRemoteRequest = 6,
  RxPdoRemoteRequest = 7,
  SdoInformation = 8,
};
std::string_view to_string(CoeService s) noexcept;

struct CoeView {
  MailboxError error = MailboxError::None;
  MailboxHeader mailbox{};
  std::uint16_t number = 0;   // 9 bits (PDO number; 0 for SDO)
  std::uint8_t service = 0;   // CoeService value, raw
  std::span<const std::uint8_t> body{};  // after the CoE header, within the mailbox length
};
CoeView decode_coe(std::span<const std::uint8_t> in) noexcept;

// ---- CoE SDO [ETG.1000.6 §5.6.2] --------------------------------------------------------------

enum class SdoCommand : std::uint8_t {
  // client -> server (CoE service 2)
  DownloadInitiateRequest,
  DownloadSegmentRequest,
  UploadInitiateRequest,
  UploadSegmentRequest,
  // server -> client (CoE service 3)
  DownloadInitiateResponse,
  DownloadSegmentResponse,
  UploadInitiateResponse,
  UploadSegmentResponse,
  // either direction (a server's abort also travels as CoE service 2, ETG.1000.6 §5.6.2.7)
  Abort,
};
std::string_view to_string(SdoCommand c) noexcept;

struct CoeSdo {
  SdoCommand command = SdoCommand::Abort;
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  bool complete_access = false;
  bool expedited = false;
  bool size_indicated = false;
  std::uint32_t size = 0;        // normal initiate: complete size; expedited with size: 1..4
  bool toggle = false;
  bool last = false;             // segments: no more segments follow
  std::span<const std::uint8_t> data{};  // expedited value, normal initiate data, segment data
  std::uint32_t abort_code = 0;
};

struct SdoView {
  MailboxError error = MailboxError::None;
  MailboxHeader mailbox{};
  CoeSdo sdo{};
};
// A mailbox the client sent (for a server) / the server sent (for the client). Specifiers are
// read by direction because the client and server codes overlap (CiA 301 §7.2.4.3).
SdoView decode_sdo_request(std::span<const std::uint8_t> in) noexcept;
SdoView decode_sdo_response(std::span<const std::uint8_t> in) noexcept;

// Client encoders (CoE service 2).
std::size_t encode_sdo_download_expedited(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                          std::uint8_t subindex, std::span<const std::uint8_t> value,
                                          bool complete_access = false) noexcept;  // value: 1..4 bytes
// Expedited download of the low `size` (1..4) bytes of `value`, little-endian.
std::size_t encode_sdo_download_value(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                      std::uint8_t subindex, std::uint32_t value, std::size_t size) noexcept;
// Normal download: complete size, then as much data as this mailbox carries (segments follow for
// the rest).
std::size_t encode_sdo_download_normal(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                       std::uint8_t subindex, std::uint32_t complete_size,
                                       std::span<const std::uint8_t> data, bool complete_access = false) noexcept;
std::size_t encode_sdo_download_segment(std::span<std::uint8_t> out, std::uint8_t counter, bool toggle, bool last,
                                        std::span<const std::uint8_t> data) noexcept;
std::size_t encode_sdo_upload_request(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                      std::uint8_t subindex, bool complete_access = false) noexcept;
std::size_t encode_sdo_upload_segment_request(std::span<std::uint8_t> out, std::uint8_t counter, bool toggle) noexcept;
// Abort from either side; CoE service 2 (SDO request) as the standard sends it.
std::size_t encode_sdo_abort(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                             std::uint8_t subindex, std::uint32_t abort_code) noexcept;

// Server encoders (CoE service 3), for the simulator.
std::size_t encode_sdo_download_response(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                         std::uint8_t subindex, bool complete_access = false) noexcept;
std::size_t encode_sdo_download_segment_response(std::span<std::uint8_t> out, std::uint8_t counter, bool toggle) noexcept;
std::size_t encode_sdo_upload_expedited_response(std::span<std::uint8_t> out, std::uint8_t counter,
                                                 std::uint16_t index, std::uint8_t subindex,
                                                 std::span<const std::uint8_t> value,
                                                 bool complete_access = false) noexcept;
std::size_t encode_sdo_upload_normal_response(std::span<std::uint8_t> out, std::uint8_t counter, std::uint16_t index,
                                              std::uint8_t subindex, std::uint32_t complete_size,
                                              std::span<const std::uint8_t> data,
                                              bool complete_access = false) noexcept;
std::size_t encode_sdo_upload_segment_response(std::span<std::uint8_t> out, std::uint8_t counter, bool toggle,
                                               bool last, std::span<const std::uint8_t> data) noexcept;

// CoE shares the CiA 301 abort codes (ETG.1000.6 §5.6.2.7.2); codes and texts live in one
// bus-neutral table: cia402::sdo_abort_code and cia402::sdo_abort_text (profiles/cia402/sdo_abort.hpp).

// ---- CoE emergency [ETG.1000.6 §5.6.4] --------------------------------------------------------

struct CoeEmergency {
  std::uint16_t error_code = 0;
  std::uint8_t error_register = 0;
  std::array<std::uint8_t, 5> data{};
  bool operator==(const CoeEmergency&) const = default;
};
struct EmergencyView {
  MailboxError error = MailboxError::None;
  MailboxHeader mailbox{};
  CoeEmergency emergency{};
};
EmergencyView decode_emergency(std::span<const std::uint8_t> in) noexcept;
std::size_t encode_emergency(std::span<std::uint8_t> out, std::uint8_t counter, const CoeEmergency& e) noexcept;

// ---- SDO Information [ETG.1000.6 §5.6.3] ------------------------------------------------------

enum class SdoInfoOpcode : std::uint8_t {
  GetOdListRequest = 1,
  GetOdListResponse = 2,
  GetObjectDescriptionRequest = 3,
  GetObjectDescriptionResponse = 4,
  GetEntryDescriptionRequest = 5,
  GetEntryDescriptionResponse = 6,
  Error = 7,
};
std::string_view to_string(SdoInfoOpcode o) noexcept;

// OD list types [ETG.1000.6 §5.6.3.3].
enum class OdListType : std::uint16_t {
  Lengths = 0,        // the response carries 5 counts: all, RxPDO, TxPDO, backup, startup
  All = 1,
  RxPdoMappable = 2,
  TxPdoMappable = 3,
  Backup = 4,         // stored for device replacement
  Startup = 5,        // startup parameters
};

// Value info flags of a Get Entry Description request/response [ETG.1000.6 §5.6.3.5].
namespace value_info {
inline constexpr std::uint8_t kUnitType = 0x08;
inline constexpr std::uint8_t kDefault = 0x10;
inline constexpr std::uint8_t kMinimum = 0x20;
inline constexpr std::uint8_t kMaximum = 0x40;
}  // namespace value_info

// Object access bits of an entry description [ETG.1000.6 §5.6.3.6].
namespace object_access {
inline constexpr std::uint16_t kReadPreOp = 0x0001;
inline constexpr std::uint16_t kReadSafeOp = 0x0002;
inline constexpr std::uint16_t kReadOp = 0x0004;
inline constexpr std::uint16_t kWritePreOp = 0x0008;
inline constexpr std::uint16_t kWriteSafeOp = 0x0010;
inline constexpr std::uint16_t kWriteOp = 0x0020;
inline constexpr std::uint16_t kRxPdoMappable = 0x0040;
inline constexpr std::uint16_t kTxPdoMappable = 0x0080;
inline constexpr std::uint16_t kBackup = 0x0100;
inline constexpr std::uint16_t kStartup = 0x0200;
}  // namespace object_access

// Object codes of an object description (CiA 301 §7.4.3).
namespace object_code {
inline constexpr std::uint8_t kVariable = 7;
inline constexpr std::uint8_t kArray = 8;
inline constexpr std::uint8_t kRecord = 9;
}  // namespace object_code

struct SdoInfoObjectDescription {
  std::uint16_t index = 0;
  std::uint16_t data_type = 0;
  std::uint8_t max_subindex = 0;
  std::uint8_t object_code = 0;
  std::string_view name{};
};

struct SdoInfoEntryDescription {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint8_t value_info = 0;
  std::uint16_t data_type = 0;
  std::uint16_t bit_length = 0;
  std::uint16_t object_access = 0;
  std::uint32_t unit_type = 0;                   // when value_info has kUnitType
  std::span<const std::uint8_t> default_value{}; // each ceil(bit_length / 8) bytes when flagged
  std::span<const std::uint8_t> minimum{};
  std::span<const std::uint8_t> maximum{};
  std::string_view name{};
};

struct SdoInfoView {
  MailboxError error = MailboxError::None;
  MailboxHeader mailbox{};
  SdoInfoOpcode opcode = SdoInfoOpcode::Error;
  bool incomplete = false;          // more fragments follow
  std::uint16_t fragments_left = 0;
  // Get OD List request: list_type. Response: list_type in the first fragment (`has_list_type`),
  // then u16 indexes; for list type 0 the five counts.
  bool has_list_type = false;
  std::uint16_t list_type = 0;
  std::span<const std::uint8_t> index_bytes{};  // u16 LE each
  std::size_t index_count() const noexcept { return index_bytes.size() / 2; }
  std::uint16_t index_at(std::size_t i) const noexcept {
    return core::get_u16(index_bytes, 2 * i);
  }
  // Get Object Description request: object.index; response: all of object.
  SdoInfoObjectDescription object{};
  // Get Entry Description request: entry.index, .subindex, .value_info; response: all of entry.
  SdoInfoEntryDescription entry{};
  std::uint32_t abort_code = 0;     // Error
};
// `first_fragment` tells the OD list decoder whether the list type precedes the indexes (the
// caller knows it from the fragments it has seen; a lone response is a first fragment).
SdoInfoView decode_sdo_info(std::span<const std::uint8_t> in, bool first_fragment = true) noexcept;

// Requests (client).
std::size_t encode_get_od_list_request(std::span<std::uint8_t> out, std::uint8_t counter, OdListType type) noexcept;
std::size_t encode_get_object_description_request(std::span<std::uint8_t> out, std::uint8_t counter,
                                                  std::uint16_t index) noexcept;
std::size_t encode_get_entry_description_request(std::span<std::uint8_t> out, std::uint8_t counter,
                                                 std::uint16_t index, std::uint8_t subindex,
                                                 std::uint8_t value_info_flags) noexcept;
// Responses (simulator). OD list: one fragment; `first` writes the list type before the indexes.
std::size_t encode_get_od_list_response(std::span<std::uint8_t> out, std::uint8_t counter, OdListType type,
                                        bool first, std::uint16_t fragments_left,
                                        std::span<const std::uint16_t> indexes) noexcept;
std::size_t encode_get_object_description_response(std::span<std::uint8_t> out, std::uint8_t counter,
                                                   const SdoInfoObjectDescription& d) noexcept;
// Entry description: the value-info data (unit, default, min, max) comes from `d` for the flags set.
std::size_t encode_get_entry_description_response(std::span<std::uint8_t> out, std::uint8_t counter,
                                                  const SdoInfoEntryDescription& d) noexcept;
std::size_t encode_sdo_info_error(std::span<std::uint8_t> out, std::uint8_t counter, std::uint32_t abort_code) noexcept;

}  // namespace drivegate::ethercat
