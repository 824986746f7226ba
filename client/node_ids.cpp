#include "client/node_ids.hpp"

#include <cctype>
#include <cstdio>

namespace drivegate::client {

namespace {

constexpr std::uint32_t kMaxNodeId = 127;  // CiA 301: node-IDs 1..127

std::string hex_id(std::uint32_t id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%02X", id);
  return buf;
}

bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }

}  // namespace

std::string format_address(std::string_view bus_type, std::uint32_t address) {
  if (bus_type.empty()) return {};
  std::string out = std::to_string(address);
  if (bus_type == "canopen") out += " (" + hex_id(address) + ")";
  return out;
}

std::string annotate_node_ids(std::string_view text) {
  constexpr std::string_view kNode = "node ";
  std::string out;
  std::size_t at = 0;
  while (at < text.size()) {
    const auto hit = text.find(kNode, at);
    if (hit == std::string_view::npos) break;
    std::size_t end = hit + kNode.size();
    while (end < text.size() && is_digit(text[end]) && end - hit - kNode.size() < 4) ++end;
    const std::size_t digits = end - hit - kNode.size();
    out.append(text.substr(at, end - at));
    at = end;
    // "node 35" as a word of its own: not "anode 3", not "node 35x" or "node 1234".
    if (digits == 0 || digits > 3 || (end < text.size() && is_digit(text[end])) ||
        (hit > 0 && (std::isalnum(static_cast<unsigned char>(text[hit - 1])) != 0)))
      continue;
    const auto id = static_cast<std::uint32_t>(std::stoul(std::string(text.substr(hit + kNode.size(), digits))));
    if (id > kMaxNodeId || text.substr(end).starts_with(" (0x")) continue;
    out += " (" + hex_id(id) + ")";
  }
  out.append(text.substr(at));
  return out;
}

}  // namespace drivegate::client
