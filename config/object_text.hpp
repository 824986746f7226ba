#pragma once
// Text forms of CiA 301/402 objects and their data types, as device profiles and configuration
// files write them: "0x6040", "0x6099:1", "u16", and PDO map entries "0x6060 i8".
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// "0x6040" or "0x6099:1" (index hex with 0x, sub-index decimal or 0x hex).
std::optional<cia402::ObjectId> parse_object_id(std::string_view text);
// "i8 u8 i16 u16 i32 u32".
std::optional<cia402::DataType> parse_data_type(std::string_view text);
const std::vector<std::string>& data_type_names();
std::string_view to_string(cia402::DataType type) noexcept;
// "6040h", "6099h:1": the form the digests and --check-config use.
std::string object_text(cia402::ObjectId id);
// "0x6040", "0x6099:1": the form configuration files write (parse_object_id reads it back).
std::string object_hex(cia402::ObjectId id);
// What tells a bus' mapped objects from a profile's cyclic objects, "" when they are the same set:
// " not mapped: 0x6040 0x6041; mapped but not <cyclic_word>: 0x6064".
std::string cyclic_image_difference(const std::vector<cia402::ObjectId>& mapped,
                                    const std::vector<cia402::ObjectId>& cyclic, std::string_view cyclic_word);
// Lowest and highest value of a type.
std::int64_t type_min(cia402::DataType type) noexcept;
std::int64_t type_max(cia402::DataType type) noexcept;

}  // namespace drivegate::config
