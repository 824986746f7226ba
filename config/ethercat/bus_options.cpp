#include "config/ethercat/bus_options.hpp"

#include <algorithm>
#include <set>

#include "config/ethercat/esi_checks.hpp"
#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

const std::vector<std::string>& transports() {
  static const std::vector<std::string> kTransports{"raw", "sim"};
  return kTransports;
}

template <typename T>
const T& option(const BusPlan& bus, const char* name) {
  return std::get<T>(bus.options.at(name));
}

void read_io(const MapReader& b, EthercatBusOptions& c) {
  const auto list = b.list("io", Need::Optional);
  if (!list) return;
  std::set<std::string> names;
  std::set<int> positions;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader m{(*list)[i], indexed(b.field("io"), i), b.source()};
    if (!m.present()) continue;
    m.check_keys({"name", "position", "vendor_id", "product_code", "inputs", "outputs", "esi"});
    EthercatIoSlave s;
    s.name = m.name("name", Need::Required).value_or("");
    s.position = static_cast<int>(m.integer("position", Need::Required, 1, 65535, "a position on the line (1 = next to the gateway)").value_or(0));
    if (const auto v = m.integer("vendor_id", Need::Optional, 0, 0xFFFFFFFF)) s.vendor_id = static_cast<std::uint32_t>(*v);
    if (const auto v = m.integer("product_code", Need::Optional, 0, 0xFFFFFFFF)) s.product_code = static_cast<std::uint32_t>(*v);
    // The process data of one slave is bounded by its SyncManager (at most 1 KiB here: one frame).
    if (const auto v = m.integer("inputs", Need::Optional, 0, 1024)) s.input_bytes = static_cast<int>(*v);
    if (const auto v = m.integer("outputs", Need::Optional, 0, 1024)) s.output_bytes = static_cast<int>(*v);
    if (!s.name.empty() && !names.insert(s.name).second) m.error("name", "I/O slave \"" + s.name + "\" is listed twice");
    if (s.position != 0 && !positions.insert(s.position).second)
      m.error("position", "position " + std::to_string(s.position) + " is given to two I/O slaves");
    // Relative to the configuration file, like every file it names.
    const std::filesystem::path base_dir = std::filesystem::absolute(std::filesystem::path{b.source().file}).parent_path();
    if (const auto esi = read_esi_key(m, base_dir, s.esi))
      check_io_slave_against_esi(m, *esi, "ESI \"" + std::filesystem::path{s.esi}.filename().string() + "\"", s);
    c.io.push_back(std::move(s));
  }
}

}  // namespace

std::vector<OptionSpec> ethercat_options() {
  const auto ms = [](double v) { return v / 1000.0; };
  return {
      {"transport", OptionKind::Choice, 0, 0, std::string{"raw"},
       "raw: an Ethernet interface given to the line (AF_PACKET, needs CAP_NET_RAW); sim: an in-process line of "
       "simulated slaves made from the axes' device profiles",
       transports()},
      {"interface", OptionKind::String, 0, 0, std::string{},
       "raw: the Ethernet interface the line is plugged into (such as eth1); the gateway owns it", {}},
      {"sm_watchdog", OptionKind::Duration, -1, 6.5, core::Duration{100ms},
       "SyncManager watchdog written to every slave (0400h/0420h): a slave whose outputs are not refreshed for "
       "this long drops to SAFE-OP and its drive reacts (6007h); 0 turns it off", {}},
      {"distributed_clocks", OptionKind::Boolean, 0, 0, true,
       "run SYNC0 on the drives whose device profile asks for distributed clocks (csp/csv/cst)", {}},
      {"sync0_shift", OptionKind::Duration, -1, 1, core::Duration{0ns},
       "SYNC0 this long after the start of the cyclic frame; must be shorter than cycle_time", {}},
      {"lost_cycles", OptionKind::Integer, 1, 1000, std::int64_t{3},
       "cycles in a row without a slave's answer (working counter short, frame lost) before its axes are lost", {}},
      {"transition_timeout", OptionKind::Duration, ms(100), 60, core::Duration{10s},
       "time a slave has for PRE-OP -> SAFE-OP and SAFE-OP -> OP", {}},
      {"sdo_timeout", OptionKind::Duration, ms(1), 10, core::Duration{1s}, "time a slave has to answer a CoE SDO request", {}},
      {"boot_retry", OptionKind::Duration, ms(10), 600, core::Duration{1s},
       "wait before the first retry of a failed slave start; doubles on every failure", {}},
      {"boot_retry_max", OptionKind::Duration, ms(10), 3600, core::Duration{10s}, "longest wait between start retries", {}},
  };
}

const char* to_string(EthercatTransportKind kind) noexcept {
  switch (kind) {
    case EthercatTransportKind::Raw: return "raw";
    case EthercatTransportKind::Simulated: return "sim";
  }
  return "?";
}

void read_ethercat_bus(const MapReader& b, const MapReader& m, BusPlan& bus) {
  auto& c = bus.sections.edit<EthercatBusOptions>();
  c.transport = option<std::string>(bus, "transport") == "sim" ? EthercatTransportKind::Simulated
                                                               : EthercatTransportKind::Raw;
  c.interface = option<std::string>(bus, "interface");
  if (c.transport == EthercatTransportKind::Raw) {
    if (c.interface.empty())
      m.error("interface", "a raw EtherCAT bus needs the Ethernet interface its line is plugged into (such as eth1)");
    else if (!is_interface_name(c.interface))
      m.error("interface", "must be a network interface name of 1 to 15 characters such as eth1, got \"" +
                               c.interface + "\"");
  } else if (m.has("interface")) {
    m.source().warning(m.mark_of("interface"), m.field("interface"), "is not used with transport sim");
  }
  c.sm_watchdog = option<core::Duration>(bus, "sm_watchdog");
  c.distributed_clocks = option<bool>(bus, "distributed_clocks");
  c.sync0_shift = option<core::Duration>(bus, "sync0_shift");
  c.lost_cycles = static_cast<int>(option<std::int64_t>(bus, "lost_cycles"));
  c.transition_timeout = option<core::Duration>(bus, "transition_timeout");
  c.sdo_timeout = option<core::Duration>(bus, "sdo_timeout");
  c.boot_retry = option<core::Duration>(bus, "boot_retry");
  c.boot_retry_max = option<core::Duration>(bus, "boot_retry_max");

  if (c.sync0_shift >= bus.cycle_time)
    m.error("sync0_shift", "must be shorter than the bus cycle_time (" + format_duration(bus.cycle_time) + "), got " +
                               format_duration(c.sync0_shift));
  // The SM watchdog counts 100 us units of the default divider (0400h = 2498: 40 ns x 2500) in a
  // 16-bit register (0420h) [ETG.1000.4 Table 54]: at most 6.5535 s, in steps of 100 us.
  if (c.sm_watchdog % 100us != 0ns)
    m.error("sm_watchdog", "must be a multiple of 100us (the watchdog counts 100us steps), got " + format_duration(c.sm_watchdog));
  if (c.sm_watchdog > 0ns && c.sm_watchdog <= bus.cycle_time * 2)
    m.error("sm_watchdog", "must be longer than two cycles (" + format_duration(bus.cycle_time * 2) +
                               ") or the slaves drop out between frames, got " + format_duration(c.sm_watchdog));
  if (c.boot_retry > c.boot_retry_max)
    m.error("boot_retry_max", "must not be shorter than boot_retry (" + format_duration(c.boot_retry) + "), got " +
                                  format_duration(c.boot_retry_max));
  if (bus.cycle_time % 1us != 0ns)
    b.error("cycle_time", "must be whole microseconds for an ethercat bus, got " + format_duration(bus.cycle_time));
  read_io(b, c);
}

}  // namespace drivegate::config
