#include "config/text_util.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <numeric>

namespace drivegate::config {

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0U : 1U)});
      diag = up;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string closest_match(std::string_view word, std::span<const std::string> candidates) {
  const std::size_t limit = std::max<std::size_t>(1, (word.size() + 2) / 3);
  std::string best;
  std::size_t best_d = limit + 1;
  for (const auto& c : candidates) {
    // The distance is at least the difference in length: skip the quadratic work for hopeless ones.
    const std::size_t gap = word.size() > c.size() ? word.size() - c.size() : c.size() - word.size();
    if (gap >= best_d) continue;
    const std::size_t d = edit_distance(word, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return best;
}

std::string did_you_mean(std::string_view word, std::span<const std::string> candidates) {
  const std::string m = closest_match(word, candidates);
  return m.empty() ? std::string{} : ", did you mean \"" + m + "\"?";
}

std::string join(std::span<const std::string> items, std::string_view sep) {
  if (items.empty()) return "(none)";
  std::string out;
  for (const auto& s : items) {
    if (!out.empty()) out += sep;
    out += s;
  }
  return out;
}

bool is_valid_name(std::string_view s, bool allow_punct) noexcept {
  if (s.empty() || s.size() > 63) return false;
  return std::all_of(s.begin(), s.end(), [allow_punct](char c) {
    const auto u = static_cast<unsigned char>(c);
    return std::isalnum(u) != 0 || c == '_' || (allow_punct && (c == '.' || c == '-'));
  });
}

std::string indexed(std::string_view list, std::size_t i) { return std::string{list} + "[" + std::to_string(i) + "]"; }

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace drivegate::config

namespace drivegate::config {

namespace {
constexpr std::size_t kEchoLimit = 60;
}

std::string clipped(std::string_view value) {
  if (value.size() <= kEchoLimit) return std::string{value};
  return std::string{value.substr(0, kEchoLimit)} + "...(" + std::to_string(value.size()) + " characters)";
}

std::string in_quotes(std::string_view value) {
  if (value.size() <= kEchoLimit) return "\"" + std::string{value} + "\"";
  return "\"" + std::string{value.substr(0, kEchoLimit)} + "\"...(" + std::to_string(value.size()) + " characters)";
}

bool is_interface_name(std::string_view s) noexcept {
  return !s.empty() && s.size() <= 15 && std::none_of(s.begin(), s.end(), [](char c) {
    return c == '/' || c == ':' || c == ' ' || c == '\t';
  });
}

std::optional<std::array<int, 4>> parse_ipv4(std::string_view s) noexcept {
  std::array<int, 4> octets{};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto dot = s.find('.');
    const std::string_view part = i < 3 ? s.substr(0, dot) : s;
    if (part.empty() || part.size() > 3 || (i < 3 && dot == std::string_view::npos)) return std::nullopt;
    int v = -1;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (ec != std::errc{} || end != part.data() + part.size() || v < 0 || v > 255) return std::nullopt;
    octets[i] = v;
    if (i < 3) s.remove_prefix(dot + 1);
  }
  return octets;
}

std::optional<std::uint32_t> parse_ipv4_host(std::string_view s) noexcept {
  const auto o = parse_ipv4(s);
  if (!o) return std::nullopt;
  std::uint32_t v = 0;
  for (const int octet : *o) v = v << 8 | static_cast<std::uint32_t>(octet);
  return v;
}

}  // namespace drivegate::config
