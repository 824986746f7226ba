#pragma once
// CiA 306 electronic data sheets (EDS): the INI file a vendor ships with a CANopen device, listing
// its object dictionary. drivegate reads only what the configuration checks need: which objects
// exist, their name, data type, access and whether they may be PDO-mapped. Sections are [XXXX]
// (an object, XXXX = hex index) and [XXXXsubN] (sub-index N, hex) with KEY=VALUE lines; keys are
// case-insensitive; lines starting with ';' are comments; other sections ([FileInfo],
// [DeviceInfo], [MandatoryObjects], ...) are skipped.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "config/config_error.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// AccessType values [CiA 306 §4.6.3]: rwr / rww are read-write objects meant for TPDOs / RPDOs.
enum class EdsAccess : std::uint8_t { ReadOnly, WriteOnly, ReadWrite, ReadWriteRead, ReadWriteWrite, Const };

// One accessible entry: a VAR object (sub-index 0) or one sub-index of an ARRAY or RECORD.
struct EdsObject {
  cia402::ObjectId id;
  std::string name;    // ParameterName
  std::string parent;  // ParameterName of the ARRAY/RECORD a sub-index belongs to; empty for a VAR
  std::uint16_t data_type = 0;  // CiA 301 data type index, e.g. 0x0007 UNSIGNED32
  EdsAccess access = EdsAccess::ReadOnly;
  bool pdo_mapping = false;
  std::string default_value;  // verbatim ("$NODEID+0x180" stays as written)
  std::optional<std::int64_t> low_limit;
  std::optional<std::int64_t> high_limit;
  int line = 0;  // line of its section header, for messages

  [[nodiscard]] bool readable() const noexcept { return access != EdsAccess::WriteOnly; }
  [[nodiscard]] bool writable() const noexcept {
    return access != EdsAccess::ReadOnly && access != EdsAccess::Const;
  }
};

// EDS files of real drives run to a few hundred kilobytes; larger ones are refused.
inline constexpr std::uint64_t kMaxEdsBytes = 16 * 1024 * 1024;

// Parses an EDS file. Problems go to `problems` as "FILE:LINE:1: [SECTION].KEY: message"; the
// result is nullopt when there was any.
std::optional<std::vector<EdsObject>> parse_eds(const std::filesystem::path& file, Problems& problems);
// The same for text in memory; `label` names it in messages.
std::optional<std::vector<EdsObject>> parse_eds_text(std::string_view text, const std::string& label,
                                                     Problems& problems);

// The entry with this index and sub-index, or nullptr.
const EdsObject* find_eds_object(std::span<const EdsObject> objects, cia402::ObjectId id) noexcept;
// The entry whose ParameterName is `name` (ASCII case-insensitive), or "PARENT.NAME" for a
// sub-index whose name alone is not unique ("Homing speeds.Speed during search for zero").
// nullptr when none or more than one matches.
const EdsObject* find_eds_object(std::span<const EdsObject> objects, std::string_view name) noexcept;

// "UNSIGNED32" for 0x0007, "0x0020" for types without a name here.
std::string eds_type_name(std::uint16_t data_type);
// Size in bits of a fixed-size basic type (BOOLEAN counts as 8: it is mapped as a byte here);
// nullopt for strings, domains and unknown types.
std::optional<std::uint8_t> eds_type_bits(std::uint16_t data_type) noexcept;
// The type an object of 1, 2 or 4 bytes is read and written as (BOOLEAN as u8); nullopt for
// others (REAL32, strings, 24..64-bit integers), which a parameter request cannot carry.
std::optional<cia402::DataType> eds_integer_type(std::uint16_t data_type) noexcept;
// "ro", "rw", ... as written in an EDS.
std::string_view to_string(EdsAccess access) noexcept;

}  // namespace drivegate::config
