#pragma once
// Byte vectors written as hex text ("01 01 00 3f"; spaces, newlines and '|' separate fields), so
// the expected bytes read like the layout tables they come from.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
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

namespace drivegate::profinet::test {

// The octets of `s`, then blanks up to `width` (visible strings of I&M records).
inline std::vector<std::uint8_t> ascii(std::string_view s, std::size_t width = 0) {
  std::vector<std::uint8_t> out(s.begin(), s.end());
  while (out.size() < width) out.push_back(' ');
  return out;
}

inline std::vector<std::uint8_t> cat(std::initializer_list<std::vector<std::uint8_t>> parts) {
  std::vector<std::uint8_t> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace drivegate::profinet::test
