#pragma once
// Byte vectors written as hex text ("01 01 00 3f"; spaces, newlines and '|' separate fields), so
// the expected bytes read like the layout tables they come from.
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace drivegate::profinet::test {

inline std::vector<std::uint8_t> hex(std::string_view s) {
  std::vector<std::uint8_t> out;
  int hi = -1;
  for (const char c : s) {
    int v = -1;
    if (c >= '0' && c <= '9') v = c - '0';
    else if (c >= 'a' && c <= 'f') v = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F') v = c - 'A' + 10;
    else if (c == ' ' || c == '\n' || c == '|') continue;
    else throw std::invalid_argument("hex: bad character");
    if (hi < 0) {
      hi = v;
    } else {
      out.push_back(static_cast<std::uint8_t>((hi << 4) | v));
      hi = -1;
    }
  }
  if (hi >= 0) throw std::invalid_argument("hex: odd digit count");
  return out;
}

inline std::vector<std::uint8_t> bytes(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }

}  // namespace drivegate::profinet::test
