#include "config/profinet/parameters.hpp"

#include <charconv>
#include <cstdint>
#include <string>

namespace drivegate::config {

namespace {

// A decimal number that fills `text` exactly, at most `max`.
bool decimal(std::string_view text, std::uint32_t max, std::uint32_t& out) {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out, 10);
  return ec == std::errc{} && end == text.data() + text.size() && out <= max;
}

}  // namespace

ParameterRef find_profidrive_parameter(const AxisPlan& axis, std::string_view name, cia402::ObjectId /*id*/) {
  ParameterRef out;
  const std::string how = "PROFIdrive axis '" + axis.spec.name +
                          "' takes parameters by PNU: p930, p930[1] (subindex 1) or r947[0], or a record as "
                          "rec:SLOT:SUBSLOT:INDEX";
  if (name.empty()) {
    // INDEX:SUB is CANopen's object address: on a PROFIdrive axis it would silently become a PNU
    // in hex.
    out.error = how;
    return out;
  }
  // p930, p930[1] or p930.1 ("r" likewise): the PNU, and the subindex when one is given.
  std::string_view pnu_text = name.substr(1);
  std::string_view sub_text;
  bool well_formed = name.front() == 'p' || name.front() == 'P' || name.front() == 'r' || name.front() == 'R';
  if (const auto at = pnu_text.find_first_of("[."); at != std::string_view::npos) {
    const bool bracket = pnu_text[at] == '[';
    sub_text = pnu_text.substr(at + 1);
    if (bracket) {
      well_formed = well_formed && sub_text.size() > 1 && sub_text.back() == ']';
      sub_text.remove_suffix(sub_text.empty() ? 0 : 1);
    }
    pnu_text = pnu_text.substr(0, at);
    well_formed = well_formed && !sub_text.empty();
  }
  std::uint32_t pnu = 0;
  std::uint32_t sub = 0;
  if (!well_formed || !decimal(pnu_text, 65535, pnu) || pnu == 0 ||
      (!sub_text.empty() && !decimal(sub_text, 0xFFFF, sub))) {
    out.error = "'" + std::string(name) + "' is not a parameter: " + how;
    return out;
  }
  if (sub > 255) {
    // The request carries the PROFIdrive subindex in 16 bits; our parameter path in 8.
    out.error = "'" + std::string(name) + "': subindex " + std::to_string(sub) + " is beyond 255, the most " +
                "drivegate addresses";
    return out;
  }
  out.id = cia402::ObjectId{static_cast<std::uint16_t>(pnu), static_cast<std::uint8_t>(sub)};
  return out;
}

}  // namespace drivegate::config
