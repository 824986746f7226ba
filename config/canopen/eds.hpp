#pragma once
// CiA 306 electronic data sheets (EDS): the INI file a vendor ships with a CANopen device, listing
// its object dictionary. drivegate reads only what the configuration checks need: which objects
// exist, their name, data type, access, limits and whether they may be PDO-mapped.
//
// Sections are [XXXX] (an object, XXXX = hex index) and [XXXXsubN] (sub-index N, hex) with
// KEY=VALUE lines; keys and section names are case-insensitive; lines starting with ';' (or '#')
// are comments. An ARRAY may instead give CompactSubObj=N, with optional [XXXXName] and
// [XXXXValue] sections naming its sub-indices and giving their defaults. [FileInfo], [DeviceInfo],
// [DummyUsage], [XXXXObjectLinks] and the other CiA 306 sections are read past.
//
// Files of other stacks deviate from CiA 306 in many small ways. Such deviations are warnings
// ("FILE:LINE:1: [SECTION].KEY: message", in Problems::warnings, so in Plan::warnings and
// `drivegated --check-config`), never a refusal: an object whose DataType, AccessType or
// ObjectType cannot be used is skipped with a warning (and listed in EdsDictionary::skipped). The
// only error is a file that yields no usable object at all; its warnings are then reported as
// errors so that the refusal says why. config/README.md lists what is accepted.
#include <compare>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "config/config_error.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// AccessType values [CiA 306 §4.6.3]: rwr / rww are read-write objects meant for TPDOs / RPDOs.
enum class EdsAccess : std::uint8_t { ReadOnly, WriteOnly, ReadWrite, ReadWriteRead, ReadWriteWrite, Const };

// A number as an EDS means it: a LowLimit/HighLimit, or a DefaultValue read with parse_eds_number.
// Integers are written in decimal, 0x hex or octal (leading 0) and cover the whole INTEGER64 and
// UNSIGNED64 ranges; REAL values are written as decimals ("4.5", "-1e3").
struct EdsNumber {
  // An integer that fits std::int64_t is held as one (so each integer has one representation);
  // only an integer above INT64_MAX is a std::uint64_t; a REAL is a double.
  std::variant<std::int64_t, std::uint64_t, double> value{std::int64_t{0}};
  // "$NODEID+0x180" (or "0x180+$NODEID", "$NODEID"): `value` is the constant part; for_node()
  // adds the node-ID.
  bool plus_node_id = false;

  [[nodiscard]] bool is_real() const noexcept { return std::holds_alternative<double>(value); }
  // The integer, when it is one and fits; nullopt for REALs (and node-relative values are not
  // resolved: see for_node()).
  [[nodiscard]] std::optional<std::int64_t> as_int64() const noexcept;
  [[nodiscard]] std::optional<std::uint64_t> as_uint64() const noexcept;
  [[nodiscard]] double as_double() const noexcept;
  // The value for a node: the constant part plus `node_id` when plus_node_id, else itself.
  [[nodiscard]] EdsNumber for_node(std::uint8_t node_id) const noexcept;
  friend bool operator==(const EdsNumber&, const EdsNumber&) = default;
};
// Numeric order (integers exactly, also between INT64 and UINT64 values; a REAL as double);
// unordered when one is relative to the node-ID and the other is not.
std::partial_ordering compare(const EdsNumber& a, const EdsNumber& b) noexcept;

// A LowLimit or HighLimit: the text as written and its value.
struct EdsLimit {
  std::string text;  // verbatim: "0xFFFFFFFFFFFFFFF6", "-1e3", "$NODEID+0x180"
  EdsNumber value;
  friend bool operator==(const EdsLimit&, const EdsLimit&) = default;
};

// The number `text` stands for: decimal, 0x hex or octal integers (optionally signed; "08" and
// "09", not octal, are read as decimal), decimal REALs, and $NODEID formulas (case-insensitive;
// "$NODEID+X", "X+$NODEID", "$NODEID"; X an integer). For a signed integer
// `data_type` (INTEGER8..INTEGER64), hex and octal values with the type's sign bit set are two's
// complement as the drive stores them: 0xFF on INTEGER8 is -1, 0xFFFFFFFFFFFFFFF6 on INTEGER64
// is -10 (on UNSIGNED64 it stays 18446744073709551606). nullopt when `text` is none of these.
std::optional<EdsNumber> parse_eds_number(std::string_view text, std::uint16_t data_type = 0) noexcept;

// One accessible entry: a VAR object (sub-index 0) or one sub-index of an ARRAY or RECORD.
struct EdsObject {
  cia402::ObjectId id;
  std::string name;    // ParameterName
  std::string parent;  // ParameterName of the ARRAY/RECORD a sub-index belongs to; empty for a VAR
  std::uint16_t data_type = 0;  // CiA 301 data type index, e.g. 0x0007 UNSIGNED32; any code is kept
  EdsAccess access = EdsAccess::ReadOnly;
  bool pdo_mapping = false;
  std::string default_value;  // verbatim ("$NODEID+0x180" stays as written)
  // Absent when not given, empty or unreadable (the latter with a warning). A $NODEID limit is kept
  // with value.plus_node_id set.
  std::optional<EdsLimit> low_limit;
  std::optional<EdsLimit> high_limit;
  int line = 0;  // line of its section header (for CompactSubObj entries: the ARRAY's), for messages

  [[nodiscard]] bool readable() const noexcept { return access != EdsAccess::WriteOnly; }
  [[nodiscard]] bool writable() const noexcept {
    return access != EdsAccess::ReadOnly && access != EdsAccess::Const;
  }
};

// An object section that could not be used; the warning about it says the same.
struct EdsSkipped {
  cia402::ObjectId id;
  bool whole_index = false;  // every sub-index of id.index (a CompactSubObj ARRAY, a bad [XXXXsubN])
  int line = 0;              // its section header
  std::string reason;        // "DataType \"UINT\" is not a number"
};

// What a file describes.
struct EdsDictionary {
  std::vector<EdsObject> objects;  // sorted by index and sub-index, each id once
  std::vector<EdsSkipped> skipped;
};

// EDS files of real drives run to a few hundred kilobytes; larger ones are refused.
inline constexpr std::uint64_t kMaxEdsBytes = 16 * 1024 * 1024;
// Warnings reported per file; the rest are counted in one last warning.
inline constexpr std::size_t kMaxEdsWarnings = 50;

// Parses an EDS file. Problems go to `problems` as "FILE:LINE:1: [SECTION].KEY: message"; the
// result is nullopt when there was an error (the file is unreadable or yields no usable object).
std::optional<EdsDictionary> load_eds(const std::filesystem::path& file, Problems& problems);
// The same for text in memory; `label` names it in messages.
std::optional<EdsDictionary> load_eds_text(std::string_view text, const std::string& label, Problems& problems);

// The entry with this index and sub-index, or nullptr.
const EdsObject* find_eds_object(std::span<const EdsObject> objects, cia402::ObjectId id) noexcept;
// The entry whose ParameterName is `name` (ASCII case-insensitive), or "PARENT.NAME" for a
// sub-index whose name alone is not unique ("Homing speeds.Speed during search for zero").
// nullptr when none or more than one matches.
const EdsObject* find_eds_object(std::span<const EdsObject> objects, std::string_view name) noexcept;
// The skipped section that would have described `id`, or nullptr.
const EdsSkipped* find_eds_skipped(std::span<const EdsSkipped> skipped, cia402::ObjectId id) noexcept;

// What a CiA 301 data type code stands for [CiA 301 §7.4.7]: the static types 0x0001..0x001B,
// the complex types 0x0020..0x0023, manufacturer-specific types 0x0040..0x005F, device-profile
// types 0x0060..0x025F, and codes CiA 301 does not define.
enum class EdsTypeKind : std::uint8_t {
  Boolean,
  SignedInteger,    // INTEGER8..INTEGER64, incl. 24, 40, 48, 56 bits
  UnsignedInteger,  // UNSIGNED8..UNSIGNED64, likewise
  Real,             // REAL32, REAL64
  String,           // VISIBLE_STRING, OCTET_STRING, UNICODE_STRING
  Time,             // TIME_OF_DAY, TIME_DIFFERENCE
  Domain,
  Complex,        // PDO_COMMUNICATION_PARAMETER, PDO_MAPPING, SDO_PARAMETER, IDENTITY
  VendorDefined,  // 0x0040..0x005F
  ProfileDefined, // 0x0060..0x025F
  Unknown,
};
EdsTypeKind eds_type_kind(std::uint16_t data_type) noexcept;
// "UNSIGNED32" for 0x0007, "INTEGER24", "REAL64", "DOMAIN", ...; "0x0040 (vendor-defined)",
// "0x0060 (device-profile-defined)", "0x0017 (unknown)" for codes without a CiA 301 name.
std::string eds_type_name(std::uint16_t data_type);
// Size in bits of a fixed-size basic type (BOOLEAN counts as 8: it is mapped as a byte here;
// TIME_OF_DAY and TIME_DIFFERENCE 48); nullopt for strings, domains, complex and unknown types.
std::optional<std::uint8_t> eds_type_bits(std::uint16_t data_type) noexcept;
// "ro", "rw", ... as written in an EDS.
std::string_view to_string(EdsAccess access) noexcept;

}  // namespace drivegate::config
