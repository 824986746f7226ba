#include "client/status_table.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "client/node_ids.hpp"

namespace drivegate::client {

namespace {

constexpr std::size_t kColumns = 10;
using Row = std::array<std::string, kColumns>;

std::string number(double v, const std::string& unit) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return unit.empty() ? std::string(buf) : std::string(buf) + " " + unit;
}

}  // namespace

std::string format_status_table(const std::vector<AxisState>& states, const std::vector<AxisLink>& links,
                                std::chrono::steady_clock::time_point now, std::chrono::milliseconds stale_after) {
  std::vector<Row> rows;
  rows.push_back({"GATEWAY", "AXIS", "ADDRESS", "LINK", "STATE", "MODE", "POSITION", "VELOCITY", "TORQUE", "FAULT"});
  for (const auto& s : states) {
    const auto link = std::find_if(links.begin(), links.end(),
                                   [&](const AxisLink& l) { return l.gateway == s.gateway && l.axis == s.axis; });
    const std::string address = link == links.end() ? "" : format_address(link->bus_type, link->address);
    std::string state = s.state;
    if (s.stopping) state += " (stopping)";
    if (now - s.received > stale_after) state += " (stale)";
    std::string fault;
    if (s.fault_code != 0 || !s.fault_text.empty()) {
      char code[16];
      std::snprintf(code, sizeof code, "0x%04X", s.fault_code);
      fault = std::string(code) + (s.fault_text.empty() ? "" : " " + s.fault_text);
    } else if (s.warning) {
      fault = "warning";
    }
    const std::string rate_unit = s.unit.empty() ? "" : s.unit + "/s";
    rows.push_back({s.gateway, s.axis, address, s.link, state, s.mode, number(s.position, s.unit), number(s.velocity, rate_unit),
                    number(s.torque, ""), fault});
  }
  std::array<std::size_t, kColumns> width{};
  for (const auto& r : rows)
    for (std::size_t c = 0; c < kColumns; ++c) width[c] = std::max(width[c], r[c].size());
  std::string out;
  for (const auto& r : rows) {
    std::string line;
    for (std::size_t c = 0; c < kColumns; ++c) {
      line += r[c];
      if (c + 1 < kColumns) line.append(width[c] - r[c].size() + 2, ' ');
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line;
    out += '\n';
  }
  return out;
}

}  // namespace drivegate::client
