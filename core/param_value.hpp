#pragma once
// Parameter values of every CiA 301 basic type (CiA 301 §7.1.6, Table 44): the type names clients
// use, the bytes on the wire (little-endian, as an SDO or CoE transfer carries them) and the text
// people read and write. Shared by the daemon (which encodes a client's text with the type it
// resolved from the EDS or the device profile) and the client library (which shows what comes
// back). Control plane only: these functions allocate.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace drivegate::core {

enum class ParamType : std::uint8_t {
  Unknown,  // not known to the gateway: a read hands the bytes over as they came
  Bool,
  I8, I16, I24, I32, I40, I48, I56, I64,
  U8, U16, U24, U32, U40, U48, U56, U64,
  R32, R64,
  VisibleString,  // ISO 646 text, one byte per character
  OctetString,
  UnicodeString,  // UTF-16LE on the wire, UTF-8 in text
  Domain,         // any bytes (vendor blobs, traces, firmware)
  TimeOfDay,      // 6 bytes: ms after midnight (28 bits) and days since 1984-01-01
  TimeDifference, // 6 bytes: ms (28 bits) and days
};

// Largest object a parameter request carries, either way.
inline constexpr std::size_t kMaxParamBytes = 4096;

// Short name ("u32", "i16", "r32", "string", "octets", "domain", ...): what `--type` takes and
// what the DDS parameter topics carry. "" for Unknown.
[[nodiscard]] std::string_view param_type_name(ParamType t) noexcept;
// CiA 301 name ("UNSIGNED32", "VISIBLE_STRING", ...); "unknown type" for Unknown.
[[nodiscard]] std::string_view param_type_cia_name(ParamType t) noexcept;
// Accepts the short names, the CiA 301 names (any case) and common aliases (uint32, int8, float,
// double, f32, f64, real32, vs, os, str, bytes). nullopt for anything else.
[[nodiscard]] std::optional<ParamType> param_type_from_name(std::string_view name) noexcept;
// The type for a CiA 301 data type index (0x0001 BOOLEAN .. 0x001B UNSIGNED64); Unknown for the
// others (complex and vendor-defined types: their bytes still travel).
[[nodiscard]] ParamType param_type_from_cia(std::uint16_t data_type) noexcept;
// Bytes of a fixed-size type; 0 for the variable ones (strings, domain) and Unknown.
[[nodiscard]] std::size_t param_type_size(ParamType t) noexcept;
[[nodiscard]] bool param_type_is_integer(ParamType t) noexcept;  // Bool counts as an integer
[[nodiscard]] bool param_type_is_signed(ParamType t) noexcept;
[[nodiscard]] bool param_type_is_real(ParamType t) noexcept;
// The integer type of 1, 2, 4 or 8 bytes; nullopt for other sizes.
[[nodiscard]] std::optional<ParamType> integer_param_type(std::size_t size, bool is_signed) noexcept;

// Text -> bytes for a write. Integers take decimal or 0x hex (hex may give a signed type's bit
// pattern: 0xFFFF is -1 as i16), a value outside the type's range is an error naming the range;
// reals take decimal or exponent notation and must be finite and within the type; booleans take
// 0/1/true/false; VISIBLE_STRING takes printable ASCII; UNICODE_STRING takes UTF-8; OCTET_STRING,
// DOMAIN and the time types take hex bytes ("01 02 0a", "01:02:0A", "0x01020a"). Unknown cannot be
// encoded (the caller must name a type).
struct EncodedParam {
  std::vector<std::uint8_t> bytes;
  std::string error;  // non-empty: not encoded
};
[[nodiscard]] EncodedParam encode_param(ParamType t, std::string_view text);

// Bytes -> value. `size_error` says why bytes do not fit the type (a fixed-size type needs exactly
// its size); empty when they do.
[[nodiscard]] std::string param_size_error(ParamType t, std::size_t size);
// The value as text: integers in decimal, reals in their shortest exact form, strings as they
// are, byte types (and Unknown) as hex bytes "01 02 0A". A size that does not fit the type gives
// the hex bytes.
[[nodiscard]] std::string format_param(ParamType t, std::span<const std::uint8_t> bytes);
// Integers as hex with the type's width ("0x00020192"); nullopt for other types or a wrong size.
[[nodiscard]] std::optional<std::string> format_param_hex(ParamType t, std::span<const std::uint8_t> bytes);
// An integer type's value (Bool too); nullopt for others or a wrong size. 64-bit unsigned values
// above INT64_MAX come back through `as_unsigned`.
[[nodiscard]] std::optional<std::int64_t> param_as_signed(ParamType t, std::span<const std::uint8_t> bytes) noexcept;
[[nodiscard]] std::optional<std::uint64_t> param_as_unsigned(ParamType t, std::span<const std::uint8_t> bytes) noexcept;
[[nodiscard]] std::optional<double> param_as_real(ParamType t, std::span<const std::uint8_t> bytes) noexcept;
// "01 02 0A".
[[nodiscard]] std::string hex_bytes(std::span<const std::uint8_t> bytes);

// Objects people read in hex first (CiA 301 identity, COB-IDs, error codes, PDO mappings, the
// CiA 402 control and status words).
[[nodiscard]] bool param_reads_as_hex(std::uint16_t index, std::uint8_t sub) noexcept;

}  // namespace drivegate::core
