#pragma once
// Manufacturer parameters named <letter><line>[<element>] (STÖBER: "A83", "E200[0]", "A00[2]")
// mapped to CANopen objects by the profile's ParameterNaming: index = base + group * group_stride
// + line with group = the letter's position in the alphabet (A = 0), sub-index = element
// [stoeber-sd6-canopen.md §2.2, test vector TV-6: E200[0] -> 28C8h:00].
#include <optional>
#include <string>
#include <string_view>

#include "config/canopen/plan.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

struct ParameterNameResult {
  std::optional<cia402::ObjectId> id;
  std::string error;  // why `id` is empty: "line 540 is beyond 511, the last line ..."
};

// The object a parameter name stands for, with the reason when there is none.
ParameterNameResult resolve_parameter_name(std::string_view name, const ParameterNaming& naming);
// The same without the reason.
std::optional<cia402::ObjectId> parse_parameter_name(std::string_view name, const ParameterNaming& naming);

}  // namespace drivegate::config
