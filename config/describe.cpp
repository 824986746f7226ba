#include "config/describe.hpp"

#include <algorithm>
#include <sstream>

#include "config/bus_types.hpp"
#include "config/object_text.hpp"
#include "config/scalars.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

// "  label:        value" with labels padded to one column.
class Printer {
 public:
  Printer(std::ostringstream& out, int indent, int width) : out_(out), indent_(indent), width_(width) {}
  // The rows a bus type adds (BusTypeInfo::describe_bus, describe_axis).
  template <typename Fn, typename... Args>
  void rows(const Fn& rows_of, const Args&... args) const {
    DescribeRows rows;
    rows_of(args..., rows);
    for (const auto& [label, value] : rows) row(label, value);
  }
  void row(const std::string& label, const std::string& value) const {
    out_ << std::string(static_cast<std::size_t>(indent_), ' ') << label << ':'
         << std::string(static_cast<std::size_t>(std::max<int>(1, width_ - static_cast<int>(label.size()))), ' ')
         << value << '\n';
  }

 private:
  std::ostringstream& out_;
  int indent_;
  int width_;
};

std::string modes_text(core::ModeSet modes) {
  std::vector<std::string> names;
  for (std::size_t i = 1; i < core::kModeCount; ++i)
    if (modes.contains(static_cast<core::Mode>(i))) names.emplace_back(core::mode_short_name(static_cast<core::Mode>(i)));
  return join(names, " ");
}

std::string option_text(const OptionValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::int64_t>) return std::to_string(x);
        else if constexpr (std::is_same_v<T, double>) return format_number(x);
        else if constexpr (std::is_same_v<T, bool>) return x ? "true" : "false";
        else if constexpr (std::is_same_v<T, std::string>) return x;
        else return format_duration(x);
      },
      v);
}

std::string limit_text(double v, const std::string& unit) {
  return v > 0 ? format_number(v) + " " + unit : "none";
}

void describe_axis(std::ostringstream& out, const AxisPlan& a, const BusPlan& bus) {
  const auto& s = a.spec;
  const std::string& u = s.user_unit;
  const std::string torque_unit = a.mechanics.rated_torque > 0 ? "Nm" : "%";
  out << "    axis " << s.name << '\n';
  const Printer p{out, 6, 22};
  p.row(bus.type_info ? bus.type_info->address_name : "address", std::to_string(a.address));
  p.row("device", a.device.name + (a.device.vendor.empty() ? "" : " (" + a.device.vendor + ")"));
  p.row("modes", modes_text(s.modes));
  p.row("default mode", s.default_mode == core::Mode::None ? "none" : std::string{core::to_string(s.default_mode)});
  p.row("mechanics", "feed " + format_number(a.mechanics.feed) + " " + u + "/load rev, gear " +
                         format_number(a.mechanics.gear_ratio) + " motor rev/load rev, encoder " +
                         format_number(a.encoder_counts_per_rev) + " counts/rev");
  p.row("position scale", format_number(s.units.position_factor()) + " drive units per " + u);
  p.row("velocity scale", format_number(s.units.velocity_factor()) + " drive units per " + u + "/s");
  p.row("acceleration scale", format_number(s.units.acceleration_factor()) + " drive units per " + u + "/s^2");
  p.row("torque scale", format_number(s.units.torque_factor()) + " drive units per " + torque_unit);
  p.row("position limits", s.limits.has_position_limits() ? format_number(s.limits.min_position) + " .. " +
                                                                format_number(s.limits.max_position) + " " + u
                                                          : "none");
  p.row("max velocity", limit_text(s.limits.max_velocity, u + "/s"));
  p.row("max acceleration", limit_text(s.limits.max_acceleration, u + "/s^2"));
  p.row("max torque", limit_text(s.limits.max_torque, torque_unit));
  p.row("default motion", "velocity " + format_number(s.defaults.velocity) + " " + u + "/s, accel " +
                              format_number(s.defaults.acceleration) + ", decel " +
                              format_number(s.defaults.deceleration) + " " + u + "/s^2");
  p.row("homing", "method " + std::to_string(s.homing.method) + ", offset " + format_number(s.homing.offset) + " " +
                      u + ", timeout " + format_duration(s.homing.timeout));
  p.row("command timeout", format_duration(s.command_timeout) + ", then " +
                               (s.timeout_stop == core::TimeoutStop::Halt ? "halt" : "quick stop"));
  p.row("enable step timeout", format_duration(s.enable_step_timeout));
  std::vector<std::string> objects;
  for (const auto& o : a.device.cyclic_objects) objects.push_back(object_text(o));
  p.row("cyclic objects", join(objects, " "));
  if (bus.type_info && bus.type_info->describe_axis) p.rows(bus.type_info->describe_axis, bus, a);
}

}  // namespace

std::string describe_plan(const Plan& plan) {
  std::ostringstream out;
  out << "configuration " << plan.file << '\n';
  const auto& g = plan.gateway;
  out << "gateway " << g.name << '\n';
  const Printer gp{out, 2, 16};
  gp.row("dds", "domain " + std::to_string(g.domain) + ", namespace " + g.ns);
  gp.row("dds network", g.dds_interfaces.empty() ? std::string{"every interface (or as the Fast DDS profile says)"}
                                                 : "UDPv4 on " + join(g.dds_interfaces) + " only");
  if (!g.dds_profiles_file.empty())
    gp.row("dds profile", g.dds_profiles_file + (g.dds_profile.empty() ? std::string{} : " (profile " + g.dds_profile + ")"));
  gp.row("dds security", g.security ? "on: certificate " + g.security->certificate + ", permissions " +
                                          g.security->permissions
                                    : std::string{"off: anyone on the DDS domain can command the axes"});
  gp.row("log level", g.log_level);
  gp.row("status rate", format_number(g.status_rate_hz) + " Hz" +
                            (g.status_keepalive > core::Duration::zero()
                                 ? " when changed, unchanged every " + format_duration(g.status_keepalive)
                                 : std::string{", every period"}));
  if (!g.device_dirs.empty()) gp.row("device dirs", join(g.device_dirs));
  for (const auto& b : plan.buses) {
    out << "  bus " << b.name << '\n';
    const Printer bp{out, 4, 16};
    bp.row("type", b.type);
    bp.row("cycle time", format_duration(b.cycle_time));
    bp.row("scheduling", (b.priority > 0 ? "SCHED_FIFO priority " + std::to_string(b.priority) : "normal") +
                             std::string{", "} + (b.cpu >= 0 ? "CPU " + std::to_string(b.cpu) : "any CPU"));
    std::vector<std::string> opts;
    for (const auto& [name, value] : b.options) opts.push_back(name + "=" + option_text(value));
    if (!opts.empty()) bp.row("options", join(opts));
    if (b.type_info)
      for (const auto& rows_of : b.type_info->describe_bus) bp.rows(rows_of, b);
    bp.row("axes", std::to_string(b.axes.size()));
    for (const auto& a : b.axes) describe_axis(out, a, b);
  }
  if (!plan.warnings.empty()) {
    out << "warnings\n";
    for (const auto& w : plan.warnings) out << "  " << w << '\n';
  }
  return out.str();
}

namespace {

// The printout as sections ("gateway demo-cell", "bus sim0", "axis x") of "key: value" rows; a key
// that repeats within a section (start-up writes) keeps all its values in order.
struct Section {
  std::string name;
  std::vector<std::pair<std::string, std::vector<std::string>>> rows;
};

std::vector<Section> sections_of(const std::string& printout) {
  std::vector<Section> out;
  std::istringstream in(printout);
  std::string line;
  while (std::getline(in, line)) {
    const auto text = line.find_first_not_of(' ');
    if (text == std::string::npos) continue;
    const std::string body = line.substr(text);
    const auto colon = body.find(": ");
    const bool heading = body.rfind("gateway ", 0) == 0 || body.rfind("bus ", 0) == 0 || body.rfind("axis ", 0) == 0;
    if (heading && colon == std::string::npos) {
      out.push_back({body, {}});
      continue;
    }
    if (out.empty() || colon == std::string::npos) continue;  // the "configuration FILE" line
    std::string key = body.substr(0, colon);
    const auto value_at = body.find_first_not_of(' ', colon + 1);
    std::string value = value_at == std::string::npos ? std::string{} : body.substr(value_at);
    auto& rows = out.back().rows;
    const auto it = std::find_if(rows.begin(), rows.end(), [&](const auto& r) { return r.first == key; });
    if (it == rows.end())
      rows.push_back({std::move(key), {std::move(value)}});
    else
      it->second.push_back(std::move(value));
  }
  return out;
}

}  // namespace

std::vector<std::string> describe_changes(const Plan& running, const Plan& next) {
  const auto before = sections_of(describe_plan(running));
  const auto after = sections_of(describe_plan(next));
  const auto find = [](const std::vector<Section>& v, const std::string& name) -> const Section* {
    for (const auto& s : v)
      if (s.name == name) return &s;
    return nullptr;
  };
  std::vector<std::string> changes;
  for (const auto& b : before)
    if (!find(after, b.name)) changes.push_back(b.name + ": removed");
  for (const auto& a : after) {
    const Section* b = find(before, a.name);
    if (!b) {
      changes.push_back(a.name + ": added");
      continue;
    }
    const auto values = [](const Section& s, const std::string& key) -> std::vector<std::string> {
      for (const auto& r : s.rows)
        if (r.first == key) return r.second;
      return {};
    };
    std::vector<std::string> keys;
    for (const auto& r : b->rows) keys.push_back(r.first);
    for (const auto& r : a.rows)
      if (std::find(keys.begin(), keys.end(), r.first) == keys.end()) keys.push_back(r.first);
    for (const auto& key : keys) {
      const auto old_v = values(*b, key);
      const auto new_v = values(a, key);
      if (old_v == new_v) continue;
      if (old_v.size() <= 1 && new_v.size() <= 1) {
        changes.push_back(a.name + ": " + key + ": " + (old_v.empty() ? "(none)" : old_v[0]) + " -> " +
                          (new_v.empty() ? "(none)" : new_v[0]));
        continue;
      }
      for (const auto& v : old_v)
        if (std::find(new_v.begin(), new_v.end(), v) == new_v.end()) changes.push_back(a.name + ": " + key + " removed: " + v);
      for (const auto& v : new_v)
        if (std::find(old_v.begin(), old_v.end(), v) == old_v.end()) changes.push_back(a.name + ": " + key + " added: " + v);
    }
  }
  return changes;
}

}  // namespace drivegate::config
