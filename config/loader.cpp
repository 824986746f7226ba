#include "config/loader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <thread>

#include "config/axis_reader.hpp"
#include "config/text_util.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// A file the gateway reads at start: relative paths start at the config file's directory; it must
// exist and be a regular file.
std::string read_file_path(const MapReader& m, std::string_view key, const fs::path& base_dir, Need need) {
  const auto given = m.string(key, need);
  if (!given) return {};
  const fs::path p{*given};
  const fs::path abs = (p.is_absolute() ? p : base_dir / p).lexically_normal();
  std::error_code ec;
  if (!fs::exists(abs, ec))
    m.error(key, "file \"" + abs.string() + "\" does not exist (relative paths start at the config file's directory)");
  else if (!fs::is_regular_file(abs, ec))
    m.error(key, "\"" + abs.string() + "\" is not a regular file");
  return abs.string();
}

// gateway.security: DDS Security (README "DDS Security"). `dir` names a directory in the layout
// scripts/make-pki.sh writes; each file may also be named on its own (and then overrides it).
std::optional<SecurityPlan> read_security(const MapReader& sec, const fs::path& base_dir) {
  static const std::vector<std::string> kFiles{"identity_ca", "certificate", "private_key",
                                               "permissions_ca", "governance", "permissions"};
  std::vector<std::string> keys = kFiles;
  keys.emplace_back("dir");
  sec.check_keys(keys);
  if (!sec.present()) return std::nullopt;
  static const std::vector<std::string> kInDir{"identity_ca.pem",    "cert.pem",       "key.pem",
                                               "permissions_ca.pem", "governance.p7s", "permissions.p7s"};
  std::array<std::string, 6> paths;
  if (const auto dir = sec.string("dir", Need::Optional)) {
    const fs::path d = fs::path{*dir}.is_absolute() ? fs::path{*dir} : base_dir / *dir;
    std::error_code ec;
    if (!fs::is_directory(d, ec))
      sec.error("dir", "directory \"" + d.lexically_normal().string() + "\" does not exist");
    for (std::size_t i = 0; i < kInDir.size(); ++i) {
      paths[i] = (d / kInDir[i]).lexically_normal().string();
      if (!sec.has(kFiles[i]) && !fs::is_regular_file(paths[i], ec))
        sec.error("dir", "\"" + paths[i] + "\" (" + kFiles[i] + ") does not exist; scripts/make-pki.sh makes the set");
    }
  }
  for (std::size_t i = 0; i < kFiles.size(); ++i) {
    if (sec.has(kFiles[i]))
      paths[i] = read_file_path(sec, kFiles[i], base_dir, Need::Required);
    else if (paths[i].empty())
      sec.error(kFiles[i], "missing: give every security file, or dir with all six");
  }
  return SecurityPlan{paths[0], paths[1], paths[2], paths[3], paths[4], paths[5]};
}

// An interface name as the kernel allows it (1..15 characters, no '/' or space) or an IPv4 address.
bool is_interface_or_address(const std::string& s) {
  if (s.empty() || s.size() > 15) return false;
  return std::none_of(s.begin(), s.end(), [](char c) { return c == '/' || c == ' ' || c == ':' || c < 33 || c > 126; });
}

void read_gateway(const MapReader& g, const fs::path& base_dir, GatewayPlan& out) {
  g.check_keys({"name", "dds", "security", "log_level", "status_rate_hz", "status_keepalive", "device_dirs"});
  out.name = g.name("name", Need::Required).value_or("");
  const MapReader dds = g.map("dds", Need::Optional);
  dds.check_keys({"domain", "namespace", "profiles_file", "profile", "interfaces", "duplicate_check"});
  // RTPS port arithmetic limits domain ids to 0..232 with the default port parameters.
  out.domain = static_cast<int>(dds.integer("domain", Need::Optional, 0, 232).value_or(0));
  out.ns = dds.name("namespace", Need::Optional, false).value_or(out.ns);
  if (dds.has("profiles_file")) out.dds_profiles_file = read_file_path(dds, "profiles_file", base_dir, Need::Required);
  // Fast DDS 2.9 applies the default profile of the file in FASTRTPS_DEFAULT_PROFILES_FILE by
  // itself, but not that of a file loaded later: the participant profile is named here.
  out.dds_profile = dds.name("profile", out.dds_profiles_file.empty() ? Need::Optional : Need::Required).value_or("");
  if (!out.dds_profile.empty() && out.dds_profiles_file.empty())
    dds.error("profile", "names a participant profile of profiles_file: give profiles_file too");
  if (const auto list = dds.list("interfaces", Need::Optional)) {
    if (list->size() == 0) dds.error("interfaces", "must name at least one interface (or leave it out for all)");
    for (std::size_t i = 0; i < list->size(); ++i) {
      const auto name = read_string((*list)[i], indexed(dds.field("interfaces"), i), dds.source());
      if (!name) continue;
      if (!is_interface_or_address(*name)) {
        dds.source().error((*list)[i].Mark(), indexed(dds.field("interfaces"), i),
                           "must be an interface name (1..15 characters) or an IPv4 address, got " + in_quotes(*name));
        continue;
      }
      out.dds_interfaces.push_back(*name);
    }
  }
  out.duplicate_check = dds.duration("duplicate_check", Need::Optional, 0ns, std::chrono::seconds(30))
                            .value_or(out.duplicate_check);
  out.security = read_security(g.map("security", Need::Optional), base_dir);
  static const std::vector<std::string> kLevels{"trace", "debug", "info", "warn", "error", "critical", "off"};
  out.log_level = g.choice("log_level", Need::Optional, kLevels).value_or(out.log_level);
  NumberRule rate{1, 1000, false, "a number in 1..1000 (Hz)"};
  out.status_rate_hz = g.number("status_rate_hz", Need::Optional, rate).value_or(out.status_rate_hz);
  // A negative minimum: zero allowed (every period). At most 500 ms: clients take a state they
  // have not heard of for 1 s as stale (client/status_table.hpp).
  out.status_keepalive = g.duration("status_keepalive", Need::Optional, core::Duration{-1}, std::chrono::milliseconds(500))
                             .value_or(out.status_keepalive);
  if (const auto dirs = g.list("device_dirs", Need::Optional)) {
    for (std::size_t i = 0; i < dirs->size(); ++i) {
      const auto dir = read_string((*dirs)[i], indexed(g.field("device_dirs"), i), g.source());
      if (!dir) continue;
      const fs::path p{*dir};
      const fs::path abs = p.is_absolute() ? p : base_dir / p;
      std::error_code ec;
      if (!fs::is_directory(abs, ec))
        g.source().error((*dirs)[i].Mark(), indexed(g.field("device_dirs"), i),
                         "directory \"" + abs.string() + "\" does not exist (relative paths start at the "
                         "config file's directory)");
      out.device_dirs.push_back(abs.lexically_normal().string());
    }
  }
}

void read_options(const MapReader& m, const BusTypeInfo& type, BusPlan& bus) {
  std::vector<std::string> keys;
  for (const auto& o : type.options) keys.push_back(o.name);
  m.check_keys(keys);
  for (const auto& o : type.options) {
    OptionValue v = o.default_value;
    switch (o.kind) {
      case OptionKind::Integer:
        if (const auto i = m.integer(o.name, Need::Optional, static_cast<std::int64_t>(o.min),
                                     static_cast<std::int64_t>(o.max)))
          v = *i;
        break;
      case OptionKind::Number:
        if (const auto d = m.number(o.name, Need::Optional,
                                    {o.min, o.max, false, "a number in " + format_number(o.min) + ".." +
                                                              format_number(o.max)}))
          v = *d;
        break;
      case OptionKind::Boolean:
        if (const auto b = m.boolean(o.name, Need::Optional)) v = *b;
        break;
      case OptionKind::String:
        if (const auto s = m.string(o.name, Need::Optional)) v = *s;
        break;
      case OptionKind::Duration: {
        const auto seconds = [](double s) { return core::Duration{std::llround(s * 1e9)}; };
        const bool ranged = o.min != 0 || o.max > 0;
        if (const auto d = m.duration(o.name, Need::Optional, ranged ? seconds(o.min) : 0ns,
                                      ranged ? seconds(o.max) : std::chrono::hours(1)))
          v = *d;
        break;
      }
      case OptionKind::Choice:
        if (const auto c = m.choice(o.name, Need::Optional, o.choices)) v = *c;
        break;
    }
    bus.options[o.name] = v;
  }
}

void read_bus(const MapReader& b, const BusTypeRegistry& registry, BusPlan& bus) {
  bus.name = b.name("name", Need::Required).value_or("");
  std::shared_ptr<const BusTypeInfo> type;
  std::vector<std::string> keys{"name", "type", "cycle_time", "priority", "cpu", "options"};
  if (const auto t = b.string("type", Need::Required)) {
    type = registry.find(*t);
    if (type) keys.insert(keys.end(), type->bus_keys.begin(), type->bus_keys.end());
    const auto available = registry.available_names();
    if (!type) {
      b.error("type", "unknown bus type " + in_quotes(*t) + did_you_mean(*t, registry.names()) +
                          " (available: " + join(available) + ")");
    } else if (!type->available()) {
      b.error("type", "bus type " + in_quotes(*t) + " has no adapter in this build (available: " + join(available) + ")");
      type = nullptr;
    } else {
      bus.type = *t;
    }
  }
  b.check_keys(keys);
  // Each bus type bounds its cycle (canopen: the SYNC period); unknown types get the widest range.
  bus.cycle_time = b.duration("cycle_time", Need::Required, type ? type->min_cycle_time : 100us,
                              type ? type->max_cycle_time : 1s)
                       .value_or(bus.cycle_time);
  if (const auto p = b.integer("priority", Need::Optional, 0, 99)) bus.priority = static_cast<int>(*p);
  // CPU_SETSIZE is 1024 on Linux; whether the CPU exists is only known on the target machine.
  if (const auto c = b.integer("cpu", Need::Optional, -1, 1023)) {
    bus.cpu = static_cast<int>(*c);
    const unsigned cpus = std::thread::hardware_concurrency();
    if (cpus > 0 && *c >= static_cast<std::int64_t>(cpus))
      b.source().warning(b.mark_of("cpu"), b.field("cpu"),
                         "this machine has " + std::to_string(cpus) + " CPUs (0.." + std::to_string(cpus - 1) + ")");
  }
  if (!type) return;
  const MapReader options = b.map("options", Need::Optional);
  read_options(options, *type, bus);
  if (type->read_bus) type->read_bus(b, options, bus);
  bus.type_info = std::move(type);
}

struct Seen {
  std::string what;
  std::map<std::string, std::string> first;  // key -> field path of the first occurrence (and its owner)
  // Reports `key` when it was seen before; returns true when it is new. `owner` names who uses it
  // ("axis \"x\""), so the message can name both users.
  bool check(const std::string& key, const MapReader& m, std::string_view field, const std::string& label,
             const std::string& owner = {}) {
    if (key.empty()) return true;
    const auto [it, added] = first.emplace(key, m.field(field) + (owner.empty() ? "" : " (" + owner + ")"));
    if (!added) m.error(field, (owner.empty() ? "" : owner + ": ") + what + " " + label + " is already used by " + it->second);
    return added;
  }
};

Plan compile(const std::string& text, const std::string& file, const LoadOptions& options) {
  Problems problems;
  const Source src{file, &problems};
  const auto doc = parse_document(text, src);
  problems.throw_if_errors();

  Plan plan;
  plan.file = file;
  const MapReader root{*doc, "", src};
  root.check_keys({"gateway", "buses", "axes"});
  const fs::path base_dir = fs::absolute(fs::path{file}).parent_path();
  read_gateway(root.map("gateway", Need::Required), base_dir, plan.gateway);

  std::vector<YAML::Mark> bus_marks;
  Seen bus_names{"bus name", {}};
  if (const auto buses = root.list("buses", Need::Required)) {
    if (buses->size() == 0) root.error("buses", "must list at least one bus");
    for (std::size_t i = 0; i < buses->size(); ++i) {
      const MapReader b{(*buses)[i], indexed("buses", i), src};
      if (!b.present()) continue;
      BusPlan bus;
      read_bus(b, options.bus_types, bus);
      bus_names.check(bus.name, b, "name", "\"" + bus.name + "\"");
      bus_marks.push_back(b.mark());
      plan.buses.push_back(std::move(bus));
    }
  }

  std::vector<fs::path> dirs(plan.gateway.device_dirs.begin(), plan.gateway.device_dirs.end());
  dirs.insert(dirs.end(), options.device_dirs.begin(), options.device_dirs.end());
  DeviceCatalog devices{dirs, options.bus_types};
  AxisContext ctx{plan.buses, options.bus_types, devices, base_dir};
  Seen axis_names{"axis name", {}};
  std::vector<Seen> addresses;
  for (const auto& bus : plan.buses) addresses.push_back(Seen{bus.type_info ? bus.type_info->address_name : "address", {}});
  std::vector<std::pair<std::size_t, AxisPlan>> axes;
  if (const auto list = root.list("axes", Need::Optional)) {
    for (std::size_t i = 0; i < list->size(); ++i) {
      const MapReader a{(*list)[i], indexed("axes", i), src};
      if (!a.present()) continue;
      ReadAxis axis = read_axis(a, ctx);
      axis_names.check(axis.plan.spec.name, a, "name", "\"" + axis.plan.spec.name + "\"");
      if (!axis.bus) continue;
      if (axis.plan.address != 0) {
        const BusPlan& bus = plan.buses[*axis.bus];
        const bool name_axes = bus.type_info && bus.type_info->reused_address_names_axes;
        const std::string key = bus.type_info && bus.type_info->address_key ? bus.type_info->address_key(axis.plan)
                                                                             : std::to_string(axis.plan.address);
        addresses[*axis.bus].check(key, a, "address",
                                   key + " on bus \"" + bus.name + "\"",
                                   name_axes ? "axis \"" + axis.plan.spec.name + "\"" : std::string{});
      }
      axes.emplace_back(*axis.bus, std::move(axis.plan));
    }
  }
  for (auto& [bus, axis] : axes) plan.buses[bus].axes.push_back(std::move(axis));
  for (std::size_t i = 0; i < plan.buses.size(); ++i) {
    if (plan.buses[i].axes.empty() && !plan.buses[i].name.empty())
      src.warning(bus_marks[i], indexed("buses", i),
                  "bus \"" + plan.buses[i].name + "\" has no axes; it will run its cycle with nothing on it");
    if (const auto& type = plan.buses[i].type_info)
      for (const auto& check : type->check_bus) check(plan.buses[i], BusEntry{src, bus_marks[i], indexed("buses", i)});
  }

  problems.throw_if_errors();
  // Each once: axes sharing an EDS file would otherwise repeat its warnings.
  for (const auto& w : problems.warnings())
    if (auto line = w.to_string(); std::find(plan.warnings.begin(), plan.warnings.end(), line) == plan.warnings.end())
      plan.warnings.push_back(std::move(line));
  return plan;
}

}  // namespace

Plan load_plan(const std::string& path, const LoadOptions& options) {
  Problems problems;
  const auto text = read_text_file(path, Source{path, &problems});
  problems.throw_if_errors();
  return compile(*text, path, options);
}

Plan load_plan_from_string(std::string_view yaml, std::string_view file_label, const LoadOptions& options) {
  return compile(std::string{yaml}, std::string{file_label}, options);
}

}  // namespace drivegate::config
