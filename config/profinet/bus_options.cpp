#include "config/profinet/bus_options.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <map>
#include <set>

#include "config/profinet/gsdml.hpp"
#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

template <typename T>
const T& option(const BusPlan& bus, const char* name) {
  return std::get<T>(bus.options.at(name));
}

bool power_of_two(std::int64_t v) noexcept { return v > 0 && std::has_single_bit(static_cast<std::uint64_t>(v)); }

std::optional<std::uint32_t> read_ipv4(const MapReader& m, std::string_view key, Need need) {
  const auto text = m.string(key, need);
  if (!text) return std::nullopt;
  const auto ip = parse_ipv4_host(*text);
  if (!ip) m.error(key, "must be an IPv4 address such as 192.168.0.10, got " + in_quotes(*text));
  return ip;
}

// What is wrong with a NameOfStation, for a message; empty when it keeps the PROFINET rules.
std::string station_name_problem(const ProfinetWireRules& rules, const std::string& name) {
  const std::string why = rules.station_name_error(name);
  if (why.empty()) return why;
  return "must be a PROFINET NameOfStation (lower case DNS labels such as akd-x1), got " + in_quotes(name) + ": " + why;
}

// One IP suite: a unicast address inside its subnet, a contiguous netmask, a gateway in the subnet.
void read_ip_suite(const MapReader& m, ProfinetStation& s) {
  const auto ip = read_ipv4(m, "ip", Need::Required);
  const auto mask = read_ipv4(m, "netmask", Need::Optional);
  const auto gateway = read_ipv4(m, "gateway", Need::Optional);
  s.netmask = mask.value_or(0xFFFFFF00U);
  if (const std::string problem = ipv4_netmask_problem(s.netmask); mask && !problem.empty()) {
    m.error("netmask", problem);
    return;
  }
  if (!ip) return;
  s.ip = *ip;
  if (const std::string problem = ipv4_host_problem(s.ip, s.netmask); !problem.empty()) m.error("ip", problem);
  if (gateway) {
    s.gateway = *gateway;
    if ((s.gateway & s.netmask) != (s.ip & s.netmask) || s.gateway == s.ip)
      m.error("gateway", "must be another address of the station's subnet " + ipv4_text(s.ip & s.netmask) + "/" +
                             std::to_string(std::popcount(s.netmask)) + ", got " + ipv4_text(s.gateway));
  }
}

void read_stations(const ProfinetWireRules& rules, const MapReader& b, ProfinetBusOptions& c) {
  const auto list = b.list("devices", Need::Optional);
  if (!list) return;
  std::map<std::string, std::string> names;       // station -> its entry
  std::map<std::uint32_t, std::string> addresses;  // ip -> its entry
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader m{(*list)[i], indexed(b.field("devices"), i), b.source()};
    if (!m.present()) continue;
    m.check_keys({"station", "ip", "netmask", "gateway", "vendor_id", "device_id"});
    ProfinetStation s;
    auto name = m.string("station", Need::Required);
    if (const std::string problem = name ? station_name_problem(rules, *name) : std::string{}; !problem.empty()) {
      m.error("station", problem);
      name.reset();
    }
    read_ip_suite(m, s);
    if (const auto v = m.integer("vendor_id", Need::Optional, 0, 0xFFFF)) s.vendor_id = static_cast<std::uint16_t>(*v);
    if (const auto v = m.integer("device_id", Need::Optional, 0, 0xFFFF)) s.device_id = static_cast<std::uint16_t>(*v);
    if (s.ip != 0)
      if (const auto [it, added] = addresses.emplace(s.ip, m.path()); !added)
        m.error("ip", "IP address " + ipv4_text(s.ip) + " is already given to " + it->second);
    if (!name) continue;
    // The controller finds a station by its name (DCP identify): one name, one device [§3.1 step 4].
    if (const auto [it, added] = names.emplace(*name, m.path()); !added) {
      m.error("station", "station " + in_quotes(*name) + " is already listed at " + it->second +
                             ": every device needs a name of its own");
      continue;
    }
    s.name = *name;
    c.stations.push_back(std::move(s));
  }
}

// "01 02 ff", "0102FF": 1..1024 octets.
std::optional<std::vector<std::uint8_t>> parse_hex_bytes(std::string_view text) {
  std::vector<std::uint8_t> out;
  int high = -1;
  for (const char ch : text) {
    if (ch == ' ' || ch == ':' || ch == '-') {
      if (high >= 0) return std::nullopt;  // a lone digit
      continue;
    }
    const int v = std::isdigit(static_cast<unsigned char>(ch)) != 0 ? ch - '0'
                  : std::isxdigit(static_cast<unsigned char>(ch)) != 0
                      ? std::tolower(static_cast<unsigned char>(ch)) - 'a' + 10
                      : -1;
    if (v < 0) return std::nullopt;
    if (high < 0) {
      high = v;
    } else {
      out.push_back(static_cast<std::uint8_t>(high << 4 | v));
      high = -1;
    }
  }
  if (high >= 0 || out.empty() || out.size() > 1024) return std::nullopt;
  return out;
}

// Slot 0 is the device access point, subslots 8000h and up its interface and ports; the modules
// of a device sit in slots 1..7FFFh, subslots 1..7FFFh [IEC 61158-6-10, Slot/SubslotNumber].
constexpr std::int64_t kMaxSlot = 0x7FFF;

void read_slot(const MapReader& s, const GsdmlFile* gsdml, ProfinetIoDevice& io) {
  s.check_keys({"slot", "subslot", "module", "module_ident", "submodule_ident", "inputs", "outputs"});
  const auto slot = s.integer("slot", Need::Required, 1, kMaxSlot, "a slot number (1..32767; 0 is the DAP)");
  if (!slot) return;
  if (s.has("module")) {
    for (const char* key : {"subslot", "module_ident", "submodule_ident", "inputs", "outputs"})
      if (s.has(key)) s.error(key, "comes from the GSDML module; give either module or the idents and lengths");
    const auto id = s.string("module", Need::Required);
    if (!id) return;
    if (gsdml == nullptr) {
      s.error("module", "names a GSDML module, but the IO device has no gsdml file");
      return;
    }
    const GsdmlModule* m = find_gsdml_module(gsdml->modules, *id);
    if (m == nullptr) {
      std::vector<std::string> ids;
      for (const auto& x : gsdml->modules) ids.push_back(x.id);
      s.error("module", "the GSDML lists no module " + in_quotes(*id) + did_you_mean(*id, ids) + " (modules: " + join(ids) + ")");
      return;
    }
    if (m->submodules.empty()) s.error("module", "GSDML module " + in_quotes(*id) + " has no submodule to plug");
    int n = 0;
    for (const auto& sub : m->submodules)
      io.submodules.push_back({static_cast<int>(*slot), sub.fixed_subslot.value_or(++n), m->ident, sub.ident,
                               sub.input_bytes, sub.output_bytes, m->id});
    return;
  }
  ProfinetIoSubmodule sub;
  sub.slot = static_cast<int>(*slot);
  sub.subslot = static_cast<int>(s.integer("subslot", Need::Optional, 1, kMaxSlot, "a subslot number (1..32767)").value_or(1));
  sub.module_ident = static_cast<std::uint32_t>(s.integer("module_ident", Need::Required, 0, 0xFFFFFFFF).value_or(0));
  sub.submodule_ident = static_cast<std::uint32_t>(s.integer("submodule_ident", Need::Required, 0, 0xFFFFFFFF).value_or(0));
  sub.input_bytes = static_cast<int>(s.integer("inputs", Need::Optional, 0, 1440, "octets of input data (0..1440)").value_or(0));
  sub.output_bytes = static_cast<int>(s.integer("outputs", Need::Optional, 0, 1440, "octets of output data (0..1440)").value_or(0));
  io.submodules.push_back(std::move(sub));
}

void read_records(const MapReader& m, ProfinetIoDevice& io) {
  const auto list = m.list("records", Need::Optional);
  if (!list) return;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader r{(*list)[i], indexed(m.field("records"), i), m.source()};
    if (!r.present()) continue;
    r.check_keys({"slot", "subslot", "index", "data"});
    ProfinetRecordWrite w;
    w.slot = static_cast<int>(r.integer("slot", Need::Required, 0, kMaxSlot, "a slot number (0..32767)").value_or(-1));
    w.subslot = static_cast<int>(r.integer("subslot", Need::Optional, 1, 0xFFFF, "a subslot number").value_or(1));
    // Records 0..7FFFh are the device's own; 8000h and up belong to the IO standard (diagnosis,
    // I&M, the controller's own parameterisation) [IEC 61158-6-10, Index].
    const auto index = r.integer("index", Need::Required, 0, 0x7FFF, "a user record index (0..0x7FFF)");
    const auto data = r.string("data", Need::Required);
    if (data) {
      if (auto bytes = parse_hex_bytes(*data))
        w.data = std::move(*bytes);
      else
        r.error("data", "must be 1..1024 octets in hex such as \"01 02 ff\", got " + in_quotes(*data));
    }
    if (w.slot < 0 || !index || w.data.empty()) continue;
    w.index = static_cast<std::uint16_t>(*index);
    const bool plugged = (w.slot == 0 && w.subslot == 1) ||
                         std::any_of(io.submodules.begin(), io.submodules.end(),
                                     [&](const ProfinetIoSubmodule& s) { return s.slot == w.slot && s.subslot == w.subslot; });
    if (!plugged)
      r.error("slot", "slot " + std::to_string(w.slot) + " subslot " + std::to_string(w.subslot) +
                          " holds no submodule of this IO device");
    else
      io.records.push_back(std::move(w));
  }
}

void read_io(const ProfinetWireRules& rules, const MapReader& b, ProfinetBusOptions& c) {
  const auto list = b.list("io", Need::Optional);
  if (!list) return;
  std::set<std::string> names;
  const fs::path base_dir = fs::absolute(fs::path{b.source().file}).parent_path();
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader m{(*list)[i], indexed(b.field("io"), i), b.source()};
    if (!m.present()) continue;
    m.check_keys({"name", "station", "gsdml", "dap", "dap_ident", "dap_submodule_ident", "slots", "records"});
    ProfinetIoDevice io;
    io.name = m.name("name", Need::Required).value_or("");
    if (!io.name.empty() && !names.insert(io.name).second) m.error("name", "IO device " + in_quotes(io.name) + " is listed twice");
    if (const auto station = m.string("station", Need::Required)) {
      io.station = *station;
      if (c.station(*station) == nullptr) {
        std::vector<std::string> known;
        for (const auto& s : c.stations) known.push_back(s.name);
        m.error("station", "unknown station " + in_quotes(*station) + did_you_mean(*station, known) +
                               " (the bus' devices: " + join(known) + ")");
      }
    }
    std::optional<GsdmlFile> gsdml;
    if (const auto file = m.string("gsdml", Need::Optional)) {
      const fs::path p{*file};
      const fs::path path = (p.is_absolute() ? p : base_dir / p).lexically_normal();
      std::error_code ec;
      if (!fs::is_regular_file(path, ec)) {
        m.error("gsdml", "file \"" + path.string() + "\" does not exist (relative paths start at the config file's directory)");
      } else {
        io.gsdml = path.string();
        gsdml = load_gsdml(path, *m.source().problems);
        if (!gsdml) m.error("gsdml", "GSDML \"" + path.string() + "\" has errors, listed with its file name");
      }
    }
    if (gsdml) {
      for (const char* key : {"dap_ident", "dap_submodule_ident"})
        if (m.has(key)) m.error(key, "comes from the GSDML's DAP; give dap to choose one");
      const auto dap_id = m.string("dap", gsdml->daps.size() == 1 ? Need::Optional : Need::Required);
      const GsdmlModule* dap = dap_id ? find_gsdml_module(gsdml->daps, *dap_id) : &gsdml->daps.front();
      if (dap == nullptr) {
        std::vector<std::string> ids;
        for (const auto& d : gsdml->daps) ids.push_back(d.id);
        m.error("dap", "the GSDML lists no device access point " + in_quotes(*dap_id) + " (DAPs: " + join(ids) + ")");
      } else {
        io.dap_ident = dap->ident;
        if (!dap->submodules.empty()) io.dap_submodule_ident = dap->submodules.front().ident;
      }
    } else if (!m.has("gsdml")) {
      if (m.has("dap")) m.error("dap", "names a GSDML device access point, but the IO device has no gsdml file");
      io.dap_ident = static_cast<std::uint32_t>(m.integer("dap_ident", Need::Required, 0, 0xFFFFFFFF).value_or(0));
      io.dap_submodule_ident = static_cast<std::uint32_t>(
          m.integer("dap_submodule_ident", Need::Optional, 0, 0xFFFFFFFF).value_or(io.dap_submodule_ident));
    }
    if (const auto slots = m.list("slots", Need::Required)) {
      for (std::size_t k = 0; k < slots->size(); ++k) {
        const MapReader s{(*slots)[k], indexed(m.field("slots"), k), m.source()};
        if (!s.present()) continue;
        const std::size_t before = io.submodules.size();
        read_slot(s, gsdml ? &*gsdml : nullptr, io);
        for (std::size_t j = before; j < io.submodules.size(); ++j)
          for (std::size_t e = 0; e < before; ++e)
            if (io.submodules[e].slot == io.submodules[j].slot && io.submodules[e].subslot == io.submodules[j].subslot)
              s.error("slot", "slot " + std::to_string(io.submodules[j].slot) + " subslot " +
                                  std::to_string(io.submodules[j].subslot) + " is given twice");
      }
      if (slots->size() == 0) m.error("slots", "must list at least one slot");
    }
    std::sort(io.submodules.begin(), io.submodules.end(), [](const auto& x, const auto& y) {
      return x.slot != y.slot ? x.slot < y.slot : x.subslot < y.subslot;
    });
    read_records(m, io);
    if (!io.submodules.empty()) {
      const auto subs = ar_submodules(io);
      if (const auto lengths = rules.cr_lengths(subs); !lengths.error.empty())
        m.error("slots", "the submodules do not fit one RT frame: " + lengths.error);
    }
    c.io.push_back(std::move(io));
  }
}

}  // namespace

std::vector<OptionSpec> profinet_options() {
  return {
      {"transport", OptionKind::Choice, 0, 0, std::string{"raw"},
       "raw: the Ethernet interface given to the network (raw socket and UDP, needs CAP_NET_RAW); sim: simulated "
       "devices inside drivegated, made from the stations' axes and IO devices",
       {"raw", "sim"}},
      {"interface", OptionKind::String, 0, 0, std::string{},
       "raw: the Ethernet interface the PROFINET network is plugged into (such as eth1)", {}},
      {"reduction_ratio", OptionKind::Integer, 1, 512, std::int64_t{16},
       "the IO data go every cycle_time x reduction_ratio (the update time); a power of two, 1..512 (RT class 1)", {}},
      {"data_hold_factor", OptionKind::Integer, 3, 7680, std::int64_t{3},
       "update times without a valid frame until a device (and the controller) take the data as lost: the "
       "watchdog; data_hold_factor x update time <= 1.92 s", {}},
      {"rt_class", OptionKind::Integer, 1, 3, std::int64_t{1}, "the real-time class; only 1 (RT) is supported", {}},
      {"dcp_timeout", OptionKind::Duration, 0.1, 60, core::Duration{3s},
       "how long DCP identify waits for a station to answer before it counts as missing", {}},
      {"ip_assignment", OptionKind::Choice, 0, 0, std::string{"temporary"},
       "temporary: the IP suite is set again at every start and lost at power off; permanent: the station "
       "stores it (the AKD overwrites its IP.* parameters)", {"temporary", "permanent"}},
      {"controller_station", OptionKind::String, 0, 0, std::string{"drivegate"},
       "the controller's own NameOfStation, sent in every connect request", {}},
  };
}

const char* to_string(ProfinetIpAssignment a) noexcept {
  return a == ProfinetIpAssignment::Permanent ? "permanent" : "temporary";
}

std::string ipv4_text(std::uint32_t a) {
  return std::to_string(a >> 24) + "." + std::to_string((a >> 16) & 0xFF) + "." + std::to_string((a >> 8) & 0xFF) + "." +
         std::to_string(a & 0xFF);
}

std::string ipv4_netmask_problem(std::uint32_t netmask) {
  if (netmask != 0 && power_of_two(std::int64_t{~netmask} + 1)) return {};
  return "must be a contiguous netmask such as 255.255.255.0, got " + ipv4_text(netmask);
}

std::string ipv4_host_problem(std::uint32_t ip, std::uint32_t netmask) {
  const std::uint32_t host = ip & ~netmask;
  if ((ip >> 24) != 0 && (ip >> 24) != 127 && (ip >> 28) < 14 && (~netmask <= 1 || (host != 0 && host != ~netmask)))
    return {};
  return "must be a unicast host address of its subnet (" + ipv4_text(ip & netmask) + "/" +
         std::to_string(std::popcount(netmask)) + "), got " + ipv4_text(ip);
}

void read_profinet_bus(const ProfinetWireRules& rules, const MapReader& b, const MapReader& m, BusPlan& bus) {
  auto& c = bus.sections.edit<ProfinetBusOptions>();
  c.simulated = option<std::string>(bus, "transport") == "sim";
  c.interface = option<std::string>(bus, "interface");
  if (c.simulated) {
    if (m.has("interface")) m.source().warning(m.mark_of("interface"), m.field("interface"), "is not used with transport sim");
  } else if (c.interface.empty()) {
    m.error("interface", "a profinet bus needs the Ethernet interface its network is plugged into (such as eth1)");
  } else if (!is_interface_name(c.interface)) {
    m.error("interface", "must be a network interface name of 1 to 15 characters such as eth1, got " + in_quotes(c.interface));
  }
  c.reduction_ratio = static_cast<int>(option<std::int64_t>(bus, "reduction_ratio"));
  c.data_hold_factor = static_cast<int>(option<std::int64_t>(bus, "data_hold_factor"));
  c.dcp_timeout = option<core::Duration>(bus, "dcp_timeout");
  c.ip_assignment =
      option<std::string>(bus, "ip_assignment") == "permanent" ? ProfinetIpAssignment::Permanent : ProfinetIpAssignment::Temporary;
  c.controller_station = option<std::string>(bus, "controller_station");
  if (const std::string problem = station_name_problem(rules, c.controller_station); !problem.empty())
    m.error("controller_station", problem);
  c.send_clock = bus.cycle_time;

  // RT class 1 only: classes 2 and 3 (IRT) need hardware-scheduled frames [§2: the AKD has RT only].
  if (const auto rt = option<std::int64_t>(bus, "rt_class"); rt != 1)
    m.error("rt_class", "only RT class 1 is supported (classes 2 and 3 are IRT, which needs scheduling hardware), got " +
                            std::to_string(rt));
  // SendClockFactor x 31.25 us with the factor a power of two [IEC 61158-6-10, SendClockFactor].
  if (bus.cycle_time % kProfinetClockBase != 0ns || !power_of_two(bus.cycle_time / kProfinetClockBase))
    b.error("cycle_time", "must be the PROFINET send clock, 31.25us x a power of two (250us, 500us, 1ms, 2ms or 4ms), got " +
                              format_duration(bus.cycle_time));
  // ReductionRatio of RT class 1: 1..512, a power of two [IEC 61158-6-10, ReductionRatio].
  if (!power_of_two(c.reduction_ratio))
    m.error("reduction_ratio", "must be a power of two (1, 2, 4 ... 512), got " + std::to_string(c.reduction_ratio));
  else if (c.data_hold_time() > kProfinetMaxDataHold)
    m.error("data_hold_factor", "data_hold_factor x update time must be at most 1.92s, got " +
                                    std::to_string(c.data_hold_factor) + " x " + format_duration(c.update_time()) + " = " +
                                    format_duration(c.data_hold_time()));
  read_stations(rules, b, c);
  read_io(rules, b, c);
}

}  // namespace drivegate::config
