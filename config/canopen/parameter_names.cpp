#include "config/canopen/parameter_names.hpp"

#include <cctype>
#include <charconv>

namespace drivegate::config {

namespace {

// Digits only (no sign, no spaces), at most `max_digits` long.
std::optional<int> parse_digits(std::string_view s, std::size_t max_digits) noexcept {
  if (s.empty() || s.size() > max_digits) return std::nullopt;
  for (const char c : s)
    if (std::isdigit(static_cast<unsigned char>(c)) == 0) return std::nullopt;
  int v = 0;
  std::from_chars(s.data(), s.data() + s.size(), v);
  return v;
}

constexpr const char* kForm = "must be a parameter name such as A83, E200[0] or A00[2] (group letter, line, optional [element])";

}  // namespace

ParameterNameResult resolve_parameter_name(std::string_view name, const ParameterNaming& naming) {
  ParameterNameResult r;
  if (name.empty() || std::isalpha(static_cast<unsigned char>(name.front())) == 0) {
    r.error = kForm;
    return r;
  }
  const int group = std::toupper(static_cast<unsigned char>(name.front())) - 'A';
  std::string_view rest = name.substr(1);
  std::optional<int> element = 0;
  if (const auto open = rest.find('['); open != std::string_view::npos) {
    if (rest.back() != ']') {
      r.error = kForm;
      return r;
    }
    element = parse_digits(rest.substr(open + 1, rest.size() - open - 2), 6);
    rest = rest.substr(0, open);
  }
  const auto line = parse_digits(rest, 6);
  if (!line || !element) {
    r.error = kForm;
    return r;
  }
  if (*line > naming.max_line) {
    r.error = "line " + std::to_string(*line) + " is beyond " + std::to_string(naming.max_line) +
              ", the last line an index window of this device reaches (stoeber-sd6-canopen.md §2.2)";
    return r;
  }
  // CANopen sub-indices are 8 bits wide, so higher elements have no object.
  if (*element > 255) {
    r.error = "element " + std::to_string(*element) + " is beyond 255, the highest CANopen sub-index";
    return r;
  }
  const long index = long{naming.base} + long{group} * long{naming.group_stride} + *line;
  if (index > 0xFFFF) {
    r.error = "group " + std::string(1, static_cast<char>('A' + group)) + " line " + std::to_string(*line) +
              " gives an index beyond FFFFh";
    return r;
  }
  r.id = cia402::ObjectId{static_cast<std::uint16_t>(index), static_cast<std::uint8_t>(*element)};
  return r;
}

std::optional<cia402::ObjectId> parse_parameter_name(std::string_view name, const ParameterNaming& naming) {
  return resolve_parameter_name(name, naming).id;
}

}  // namespace drivegate::config
