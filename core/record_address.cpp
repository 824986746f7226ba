#include "core/record_address.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <limits>

namespace drivegate::core {

namespace {

// Decimal or 0x hex, at most `max`.
std::optional<std::uint32_t> number(std::string_view text, std::uint32_t max) noexcept {
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  }
  std::uint64_t v = 0;
  if (text.empty()) return std::nullopt;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v, base);
  if (ec != std::errc{} || end != text.data() + text.size() || v > max) return std::nullopt;
  return static_cast<std::uint32_t>(v);
}

}  // namespace

bool is_record_address(std::string_view text) noexcept {
  return text.size() >= 4 && std::tolower(static_cast<unsigned char>(text[0])) == 'r' &&
         std::tolower(static_cast<unsigned char>(text[1])) == 'e' &&
         std::tolower(static_cast<unsigned char>(text[2])) == 'c' && text[3] == ':';
}

ParsedRecordAddress parse_record_address(std::string_view text) {
  ParsedRecordAddress out;
  const auto fail = [&](const std::string& why) {
    out.error = "record address '" + std::string(text) + "': " + why + "; write " + std::string(kRecordSyntax) +
                " (decimal or 0x hex), e.g. rec:0:1:0xAFF0 for I&M0 of the DAP";
    return out;
  };
  if (!is_record_address(text)) return fail("it does not start with rec:");
  std::string_view rest = text.substr(4);
  RecordAddress a;
  a.valid = true;
  if (const auto at = rest.find('@'); at != std::string_view::npos) {
    const auto api = number(rest.substr(at + 1), std::numeric_limits<std::uint32_t>::max());
    if (!api) return fail("the API '" + std::string(rest.substr(at + 1)) + "' is no 32-bit number");
    a.api = *api;
    a.api_given = true;
    rest = rest.substr(0, at);
  }
  std::uint16_t* const fields[] = {&a.slot, &a.subslot, &a.index};
  const char* const names[] = {"slot", "subslot", "index"};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto colon = rest.find(':');
    if ((colon == std::string_view::npos) != (k == 2))
      return fail(k == 2 ? "more than three numbers" : "a slot, a subslot and an index are needed");
    const std::string_view part = rest.substr(0, colon);
    const auto v = number(part, 0xFFFF);
    if (!v) return fail(std::string("the ") + names[k] + " '" + std::string(part) + "' is no number of 0..0xFFFF");
    *fields[k] = static_cast<std::uint16_t>(*v);
    if (colon != std::string_view::npos) rest.remove_prefix(colon + 1);
  }
  out.address = a;
  return out;
}

std::string format_record_address(const RecordAddress& a) {
  char buf[64];
  if (a.api_given)
    std::snprintf(buf, sizeof buf, "rec:%u:%u:0x%04X@0x%X", static_cast<unsigned>(a.slot),
                  static_cast<unsigned>(a.subslot), static_cast<unsigned>(a.index), static_cast<unsigned>(a.api));
  else
    std::snprintf(buf, sizeof buf, "rec:%u:%u:0x%04X", static_cast<unsigned>(a.slot), static_cast<unsigned>(a.subslot),
                  static_cast<unsigned>(a.index));
  return buf;
}

}  // namespace drivegate::core
