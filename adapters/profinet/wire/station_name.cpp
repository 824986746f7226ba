#include "adapters/profinet/wire/station_name.hpp"

#include <algorithm>
#include <cstddef>

namespace drivegate::profinet {

namespace {

bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }

bool all_digits(std::string_view s) noexcept { return !s.empty() && std::all_of(s.begin(), s.end(), is_digit); }

// "port-xyz" or "port-xyz-abcde" (reserved for the port names the LLDP neighbourhood checks use).
bool is_port_name(std::string_view label) noexcept {
  if (label.size() != 8 && label.size() != 14) return false;
  if (label.substr(0, 5) != "port-" || !all_digits(label.substr(5, 3))) return false;
  return label.size() == 8 || (label[8] == '-' && all_digits(label.substr(9, 5)));
}

// n.n.n.n, each n one to three digits.
bool looks_like_ipv4(std::string_view name) noexcept {
  int parts = 0;
  std::size_t start = 0;
  while (start <= name.size()) {
    const std::size_t dot = name.find('.', start);
    const std::size_t end = dot == std::string_view::npos ? name.size() : dot;
    const std::string_view part = name.substr(start, end - start);
    if (part.size() > 3 || !all_digits(part)) return false;
    ++parts;
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  return parts == 4;
}

}  // namespace

std::string_view to_string(NameError e) noexcept {
  switch (e) {
    case NameError::None: return "valid";
    case NameError::Empty: return "the name is empty";
    case NameError::TooLong: return "the name is longer than 240 characters";
    case NameError::EmptyLabel: return "the name has an empty label (a '.' at the start, at the end or twice in a row)";
    case NameError::LabelTooLong: return "a label (the text between dots) is longer than 63 characters";
    case NameError::UpperCase: return "the name has upper-case letters; PROFINET names are lower case";
    case NameError::InvalidCharacter: return "the name has a character other than a-z, 0-9, '-' and '.'";
    case NameError::HyphenAtLabelEdge: return "a label begins or ends with '-'";
    case NameError::LooksLikePortName: return "the first label has the form port-xyz or port-xyz-abcde, which is reserved for ports";
    case NameError::IdnaPrefix: return "the name begins with \"xn-\", which is not allowed";
    case NameError::LooksLikeIpAddress: return "the name has the form n.n.n.n of an IP address";
  }
  return "?";
}

NameError validate_name_of_station(std::string_view name) noexcept {
  if (name.empty()) return NameError::Empty;
  if (name.size() > kMaxNameOfStationLength) return NameError::TooLong;
  for (const char c : name) {
    if (c >= 'A' && c <= 'Z') return NameError::UpperCase;
    if (!((c >= 'a' && c <= 'z') || is_digit(c) || c == '-' || c == '.')) return NameError::InvalidCharacter;
  }
  std::size_t start = 0;
  bool first = true;
  while (true) {
    const std::size_t dot = name.find('.', start);
    const std::size_t end = dot == std::string_view::npos ? name.size() : dot;
    const std::string_view label = name.substr(start, end - start);
    if (label.empty()) return NameError::EmptyLabel;
    if (label.size() > kMaxLabelLength) return NameError::LabelTooLong;
    if (label.front() == '-' || label.back() == '-') return NameError::HyphenAtLabelEdge;
    if (first && is_port_name(label)) return NameError::LooksLikePortName;
    first = false;
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  if (name.substr(0, 3) == "xn-") return NameError::IdnaPrefix;
  if (looks_like_ipv4(name)) return NameError::LooksLikeIpAddress;
  return NameError::None;
}

}  // namespace drivegate::profinet
