#include "config/profinet/describe.hpp"

#include <bit>
#include <cstdio>

#include "config/profinet/bus_options.hpp"
#include "config/scalars.hpp"
#include "config/text_util.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace drivegate::config {

namespace {

std::string hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, v);
  return buf;
}

// The frame IDs the controller proposes for the k-th AR in the RT class 1 unicast range
// (C000h..F7FFh) [IEC 61158-6-10, FrameID]; the connect response gives the ones used.
std::string ar_row(const ProfinetBusOptions& o, std::size_t k, const std::string& station,
                   const ProfinetCrLengths& lengths) {
  if (!lengths.error.empty()) return station + ": " + lengths.error;
  const auto frame = static_cast<std::uint32_t>(0xC000 + 2 * k);
  return station + ": input IOCR frame " + hex(frame, 4) + " C_SDU " + std::to_string(lengths.input) + " octets (" +
         std::to_string(lengths.input_used) + " used), output IOCR frame " + hex(frame + 1, 4) + " C_SDU " +
         std::to_string(lengths.output) + " octets (" + std::to_string(lengths.output_used) + " used), every " +
         format_duration(o.send_clock) + " x " + std::to_string(o.reduction_ratio) + " = " + format_duration(o.update_time()) +
         ", watchdog " + std::to_string(o.data_hold_factor) + " x " + format_duration(o.update_time()) + " = " +
         format_duration(o.data_hold_time());
}

// "STW1 w1, MDI_TARPOS w4-5, ..." (words 1-based as the digest's tables count them).
std::string words_text(std::span<const profidrive::SignalSlot> slots) {
  std::vector<std::string> out;
  for (const auto& s : slots) {
    const auto* info = profidrive::find_signal(static_cast<std::uint16_t>(s.signal));
    const int first = s.word + 1;
    const std::string name = info ? std::string{info->name} : std::to_string(static_cast<unsigned>(s.signal));
    out.push_back(name + " w" + std::to_string(first) + (info && info->words == 2 ? "-" + std::to_string(first + 1) : ""));
  }
  return join(out);
}

}  // namespace

void describe_profinet_bus(const ProfinetWireRules& rules, const BusPlan& bus, DescribeRows& rows) {
  const auto& o = bus.section<ProfinetBusOptions>();
  rows.emplace_back("update time", format_duration(o.send_clock) + " send clock x reduction ratio " +
                                       std::to_string(o.reduction_ratio) + " = " + format_duration(o.update_time()) +
                                       ", RT class 1, data hold " + format_duration(o.data_hold_time()));
  rows.emplace_back("controller", "station " + o.controller_station + " on " + o.interface + ", IP suites set " +
                                      to_string(o.ip_assignment) + ", DCP identify timeout " + format_duration(o.dcp_timeout));
  for (const auto& s : o.stations) {
    std::string row = s.name + " " + ipv4_text(s.ip) + "/" + std::to_string(std::popcount(s.netmask));
    if (s.gateway != 0) row += " gateway " + ipv4_text(s.gateway);
    if (s.vendor_id) row += ", vendor " + hex(*s.vendor_id, 4);
    if (s.device_id) row += ", device " + hex(*s.device_id, 4);
    rows.emplace_back("station", row);
  }
  std::size_t k = 0;
  for (const auto& a : bus.axes) {
    const auto& ax = a.section<ProfinetAxisSpec>();
    const auto size = profidrive::telegram_size(ax.telegram);
    if (!size) continue;
    const auto subs = ar_submodules(ax, static_cast<int>(size->setpoint_bytes), static_cast<int>(size->actual_bytes));
    rows.emplace_back("ar", ar_row(o, k++, ax.station, rules.cr_lengths(subs)));
  }
  for (const auto& io : o.io) {
    rows.emplace_back("ar", ar_row(o, k++, io.station, rules.cr_lengths(ar_submodules(io))));
    std::vector<std::string> subs;
    for (const auto& s : io.submodules)
      subs.push_back(std::to_string(s.slot) + "/" + std::to_string(s.subslot) + " module " + hex(s.module_ident, 8) +
                     " submodule " + hex(s.submodule_ident, 8) + " in " + std::to_string(s.input_bytes) + " out " +
                     std::to_string(s.output_bytes) + (s.gsdml_id.empty() ? "" : " (" + s.gsdml_id + ")"));
    rows.emplace_back("io", io.name + " at " + io.station + ": DAP " + hex(io.dap_ident, 8) + ", slots " + join(subs) +
                                ", " + std::to_string(io.records.size()) + " record writes" +
                                (io.gsdml.empty() ? "" : ", GSDML " + io.gsdml));
  }
}

void describe_profinet_axis(const BusPlan& bus, const AxisPlan& axis, DescribeRows& rows) {
  const auto& ax = axis.section<ProfinetAxisSpec>();
  const ProfinetStation* s = bus.section<ProfinetBusOptions>().station(ax.station);
  rows.emplace_back("station", ax.station + (s ? " (" + ipv4_text(s->ip) + ")" : std::string{}) + ", telegram " +
                                   std::to_string(ax.telegram) + " in slot " + std::to_string(ax.slot) + " subslot " +
                                   std::to_string(ax.subslot));
  if (const auto layout = profidrive::standard_layout(ax.telegram)) {
    rows.emplace_back("setpoint words", std::to_string(layout->setpoint_words) + ": " + words_text(layout->setpoint_slots()));
    rows.emplace_back("actual words", std::to_string(layout->actual_words) + ": " + words_text(layout->actual_slots()));
  } else if (const auto size = profidrive::telegram_size(ax.telegram)) {
    rows.emplace_back("telegram words", std::to_string(size->setpoint_bytes / 2) + " setpoint, " +
                                            std::to_string(size->actual_bytes / 2) +
                                            " actual: the free mapping is read from the drive at start (PNU 915/916)");
  }
}

}  // namespace drivegate::config
