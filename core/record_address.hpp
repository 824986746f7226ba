#pragma once
// PROFINET record addresses as people write them for `drivegatectl param` and the DDS parameter
// topic's `name`: "rec:SLOT:SUBSLOT:INDEX" with an optional "@API", each number decimal or 0x hex
// (slot, subslot and index 0..0xFFFF, the API 32 bits) [IEC 61158-6-10 IODReadReq/IODWriteReq].
// The "rec:" prefix keeps them apart from PNUs ("p930"), object indices ("6041h:00") and names.
// Control plane only: these functions allocate.
#include <optional>
#include <string>
#include <string_view>

#include "core/command.hpp"

namespace drivegate::core {

inline constexpr std::string_view kRecordSyntax = "rec:SLOT:SUBSLOT:INDEX[@API]";

// True when `text` is meant as a record address (starts with "rec:", any case), whether or not
// the rest parses.
[[nodiscard]] bool is_record_address(std::string_view text) noexcept;

struct ParsedRecordAddress {
  std::optional<RecordAddress> address;
  std::string error;  // why not, naming the syntax
};
[[nodiscard]] ParsedRecordAddress parse_record_address(std::string_view text);

// "rec:0:1:0xAFF0@0x0" as the address reads back (the API only when given).
[[nodiscard]] std::string format_record_address(const RecordAddress& a);

}  // namespace drivegate::core
