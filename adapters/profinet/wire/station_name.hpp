#pragma once
// NameOfStation rules [IEC 61158-6-10 §4.3, coding of the field NameOfStation (DNS labels as in
// RFC 1035, RFC 5890)]: the name a controller addresses a device by, set with DCP and searched with Identify.
//
//   1..240 octets; one or more labels separated by '.'; each label 1..63 octets of 'a'-'z',
//   '0'-'9' and '-', not beginning or ending with '-'; the first label not "port-xyz" or
//   "port-xyz-abcde" (x, y, z, a..e digits: reserved for port names); not "xn-" at the start
//   (IDNA A-labels are not allowed); the whole name not of the form n.n.n.n with n 0..999 (it
//   would read as an IPv4 address).
//
// Upper-case letters are refused, not folded: the standard stores and compares the name as
// written, so "Drive-1" would never match a device called "drive-1".
#include <cstdint>
#include <string_view>

namespace drivegate::profinet {

inline constexpr std::size_t kMaxNameOfStationLength = 240;
inline constexpr std::size_t kMaxLabelLength = 63;

enum class NameError : std::uint8_t {
  None,
  Empty,
  TooLong,             // more than 240 octets
  EmptyLabel,          // ".." or a '.' at the start or the end
  LabelTooLong,        // a label of more than 63 octets
  UpperCase,           // 'A'-'Z'
  InvalidCharacter,    // anything but 'a'-'z', '0'-'9', '-', '.'
  HyphenAtLabelEdge,   // a label that begins or ends with '-'
  LooksLikePortName,   // first label "port-xyz" or "port-xyz-abcde"
  IdnaPrefix,          // begins with "xn-"
  LooksLikeIpAddress,  // n.n.n.n with n 0..999
};
std::string_view to_string(NameError e) noexcept;

// The first rule `name` breaks, None when it is a valid NameOfStation.
NameError validate_name_of_station(std::string_view name) noexcept;

}  // namespace drivegate::profinet
