#include "config/scalars.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <utility>

namespace drivegate::config {

std::optional<double> parse_number(std::string_view text) noexcept {
  bool negative = false;
  std::string_view body = text;
  if (!body.empty() && (body.front() == '+' || body.front() == '-')) {
    negative = body.front() == '-';
    body.remove_prefix(1);
  }
  // YAML 1.2 core schema spellings of infinity and not-a-number.
  if (body == ".inf" || body == ".Inf" || body == ".INF")
    return negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  if (text == ".nan" || text == ".NaN" || text == ".NAN") return std::numeric_limits<double>::quiet_NaN();
  if (body.empty() || !(std::isdigit(static_cast<unsigned char>(body.front())) != 0 || body.front() == '.'))
    return std::nullopt;  // refuses "inf", "nan" and a second sign, which from_chars would take
  if (const auto i = parse_integer(text); i) return static_cast<double>(*i);
  double v = 0;
  const auto [end, ec] = std::from_chars(body.data(), body.data() + body.size(), v);
  if (ec != std::errc{} || end != body.data() + body.size()) return std::nullopt;
  return negative ? -v : v;
}

std::optional<std::int64_t> parse_integer(std::string_view text) noexcept {
  bool negative = false;
  std::string_view body = text;
  if (!body.empty() && (body.front() == '+' || body.front() == '-')) {
    negative = body.front() == '-';
    body.remove_prefix(1);
  }
  int base = 10;
  if (body.size() > 2 && body[0] == '0' && (body[1] == 'x' || body[1] == 'X')) {
    base = 16;
    body.remove_prefix(2);
  }
  if (body.empty() || body.front() == '+' || body.front() == '-') return std::nullopt;
  std::uint64_t magnitude = 0;
  const auto [end, ec] = std::from_chars(body.data(), body.data() + body.size(), magnitude, base);
  if (ec != std::errc{} || end != body.data() + body.size()) return std::nullopt;
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  if (magnitude > kMax) return std::nullopt;
  const auto v = static_cast<std::int64_t>(magnitude);
  return negative ? -v : v;
}

namespace {
struct UnitScale {
  std::string_view suffix;
  double ns;
};
// Longest suffixes first so that "ms" is not read as "s".
constexpr std::array<UnitScale, 5> kUnits{{{"min", 60e9}, {"ns", 1.0}, {"us", 1e3}, {"ms", 1e6}, {"s", 1e9}}};
}  // namespace

std::optional<core::Duration> parse_duration(std::string_view text) noexcept {
  double scale = 1e9;  // a bare number is seconds
  std::string_view number = text;
  for (const auto& u : kUnits) {
    if (number.size() > u.suffix.size() && number.ends_with(u.suffix)) {
      number.remove_suffix(u.suffix.size());
      scale = u.ns;
      break;
    }
  }
  while (!number.empty() && number.back() == ' ') number.remove_suffix(1);
  const auto v = parse_number(number);
  if (!v || !std::isfinite(*v)) return std::nullopt;
  const double ns = *v * scale;
  if (std::fabs(ns) > 9e18) return std::nullopt;
  return core::Duration{std::llround(ns)};
}

std::string format_duration(core::Duration d) {
  const std::int64_t ns = d.count();
  constexpr std::array<std::pair<std::int64_t, std::string_view>, 4> kSteps{
      {{1'000'000'000, "s"}, {1'000'000, "ms"}, {1'000, "us"}, {1, "ns"}}};
  for (const auto& [unit, name] : kSteps)
    if (ns % unit == 0) return std::to_string(ns / unit) + std::string{name};
  return std::to_string(ns) + "ns";
}

}  // namespace drivegate::config
