#include "config/axis_reader.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

constexpr core::Duration kMaxTimeout = std::chrono::hours(1);

std::vector<std::string> mode_names(core::ModeSet modes) {
  std::vector<std::string> out;
  for (std::size_t i = 1; i < core::kModeCount; ++i) {
    const auto m = static_cast<core::Mode>(i);
    if (modes.contains(m)) out.emplace_back(core::mode_short_name(m));
  }
  return out;
}

std::vector<std::string> bus_names(const std::vector<BusPlan>& buses) {
  std::vector<std::string> out;
  for (const auto& b : buses) out.push_back(b.name);
  return out;
}

std::string int_list(const std::vector<std::int16_t>& v) {
  std::vector<std::string> s;
  for (const auto i : v) s.push_back(std::to_string(i));
  return join(s);
}

const DeviceProfile* read_device(const MapReader& axis, AxisContext& ctx) {
  const auto name = axis.name("device", Need::Required);
  if (!name) return nullptr;
  if (!ctx.devices.locate(*name)) {
    const auto available = ctx.devices.available();
    std::vector<std::string> dirs;
    for (const auto& d : ctx.devices.dirs()) dirs.push_back(d.string());
    axis.error("device", "unknown device profile " + in_quotes(*name) + did_you_mean(*name, available) +
                             " (available: " + join(available) + "; searched: " + join(dirs) + ")");
    return nullptr;
  }
  const DeviceProfile* device = ctx.devices.get(*name, *axis.source().problems);
  if (!device)
    axis.error("device", "device profile \"" + *name + "\" (" + ctx.devices.locate(*name)->string() +
                             ") has errors, listed with its file name");
  return device;
}

// Sane ranges (config/README.md "Ranges"): wide enough for any real machine, narrow enough that
// no accepted value makes a conversion overflow or round every command to nothing.
constexpr double kMaxCounts = 4294967296.0;  // 2^32 counts per motor revolution
constexpr double kMaxRatio = 1e6;            // gear ratio and feed
constexpr double kMaxTorque = 1e6;           // percent or Nm

void read_mechanics(const MapReader& m, const DeviceProfile* device, AxisPlan& a) {
  m.check_keys({"encoder_counts_per_rev", "gear_ratio", "feed", "rated_torque"});
  const bool counts_needed = device && device->units.position_base == UnitBase::EncoderCounts;
  const auto counts = m.number("encoder_counts_per_rev", counts_needed ? Need::Required : Need::Optional,
                               NumberRule::range(1, kMaxCounts, "a number of counts per motor revolution in 1..2^32"));
  const NumberRule ratio = NumberRule::range(1e-6, kMaxRatio);
  a.mechanics.gear_ratio = m.number("gear_ratio", Need::Optional, ratio).value_or(1.0);
  a.mechanics.feed = m.number("feed", Need::Optional, ratio).value_or(1.0);
  const auto rated = m.number("rated_torque", Need::Optional,
                              NumberRule::range(0, kMaxTorque, "0 (torque in percent) or a torque in 0.001..1e6 Nm"));
  if (rated && *rated > 0 && *rated < 1e-3)
    m.error("rated_torque", "must be 0 (torque in percent) or a torque in 0.001..1e6 Nm, got " + format_number(*rated));
  else
    a.mechanics.rated_torque = rated.value_or(0.0);
  if (device) {
    // Without an encoder resolution, a device with fixed position units defines the revolution.
    a.encoder_counts_per_rev = counts.value_or(device->units.position_base == UnitBase::Fixed
                                                   ? device->units.position_per_rev
                                                   : 1.0);
    a.native = device->units.resolve(a.encoder_counts_per_rev);
    a.spec.units = core::UnitConverter(a.mechanics, a.native);
    // Each factor alone is in range; together they must still give a usable scaling.
    const double f = a.spec.units.position_factor();
    if (!(f >= 1e-6 && f <= 1e15))
      m.error(m.has("feed") ? "feed" : "gear_ratio",
              "gives " + format_number(f) + " drive position units per " + a.spec.user_unit +
                  " with this encoder, gear ratio and feed; it must be in 1e-06..1e15");
  }
}

// A user-unit value must still fit the drive's 32-bit objects after scaling (607Dh, 607Fh, ...).
void check_fits_int32(const MapReader& m, std::string_view key, double drive_value) {
  if (!core::to_int32(drive_value))
    m.error(key, "is " + format_number(drive_value) +
                     " in drive units with this axis' scaling, beyond the drive's 32-bit range");
}

void read_limits(const MapReader& m, AxisPlan& a, bool scaled) {
  m.check_keys({"min_position", "max_position", "max_velocity", "max_acceleration", "max_torque"});
  auto& l = a.spec.limits;
  const NumberRule position = NumberRule::range(-kMaxUserValue, kMaxUserValue);
  const auto min = m.number("min_position", Need::Optional, position);
  const auto max = m.number("max_position", Need::Optional, position);
  if (m.has("min_position") != m.has("max_position")) {
    m.error(m.has("min_position") ? "max_position" : "min_position",
            "missing: give both min_position and max_position, or neither for no position limits");
  } else if (min && max) {
    if (*min >= *max) {
      m.error("min_position", "must be less than max_position (" + format_number(*max) + "), got " +
                                  format_number(*min));
    } else {
      l.min_position = *min;
      l.max_position = *max;
      if (scaled) {
        check_fits_int32(m, "min_position", a.spec.units.position_to_drive(*min));
        check_fits_int32(m, "max_position", a.spec.units.position_to_drive(*max));
      }
    }
  }
  const NumberRule rate = NumberRule::positive_up_to(kMaxUserValue);
  l.max_velocity = m.number("max_velocity", Need::Optional, rate).value_or(0.0);
  l.max_acceleration = m.number("max_acceleration", Need::Optional, rate).value_or(0.0);
  l.max_torque = m.number("max_torque", Need::Optional, NumberRule::positive_up_to(kMaxTorque)).value_or(0.0);
  if (scaled && l.max_velocity > 0 && !core::to_uint32(a.spec.units.velocity_to_drive(l.max_velocity)))
    m.error("max_velocity", "is beyond the drive's 32-bit velocity range with this axis' scaling");
}

std::optional<core::Mode> read_mode(const MapReader& m, std::string_view key, const DeviceProfile* device) {
  const YAML::Node n = m.find(key);
  if (!n.IsDefined()) return std::nullopt;
  const auto mode = n.IsScalar() ? core::parse_mode(n.Scalar()) : std::nullopt;
  if (!mode || *mode == core::Mode::None) {
    m.error(key, "must be a mode name such as profile_position or pp (pp, pv, vl, tq, hm, ip, csp, csv, cst, tb), got " +
                     describe_value(n));
    return std::nullopt;
  }
  if (device && !device->modes.contains(*mode)) {
    m.error(key, "device \"" + device->name + "\" does not support mode " + n.Scalar() +
                     "; supported: " + join(mode_names(device->modes)));
    return std::nullopt;
  }
  return mode;
}

void read_defaults(const MapReader& m, const DeviceProfile* device, AxisPlan& a) {
  m.check_keys({"mode", "velocity", "acceleration", "deceleration", "torque_slope"});
  auto& d = a.spec.defaults;
  a.spec.default_mode = read_mode(m, "mode", device).value_or(core::Mode::None);
  const NumberRule rate = NumberRule::positive_up_to(kMaxUserValue);
  d.velocity = m.number("velocity", Need::Optional, rate).value_or(0.0);
  d.acceleration = m.number("acceleration", Need::Optional, rate).value_or(0.0);
  d.deceleration = m.number("deceleration", Need::Optional, rate).value_or(0.0);
  d.torque_slope = m.number("torque_slope", Need::Optional, NumberRule::range(0, kMaxUserValue)).value_or(0.0);
  const auto& l = a.spec.limits;
  if (l.max_velocity > 0 && d.velocity > l.max_velocity)
    m.error("velocity", "must not exceed limits.max_velocity (" + format_number(l.max_velocity) + "), got " +
                            format_number(d.velocity));
  if (l.max_acceleration > 0 && d.acceleration > l.max_acceleration)
    m.error("acceleration", "must not exceed limits.max_acceleration (" + format_number(l.max_acceleration) +
                                "), got " + format_number(d.acceleration));
  if (l.max_acceleration > 0 && d.deceleration > l.max_acceleration)
    m.error("deceleration", "must not exceed limits.max_acceleration (" + format_number(l.max_acceleration) +
                                "), got " + format_number(d.deceleration));
}

bool supports_method(const DeviceProfile& device, std::int64_t method) {
  return device.homing_methods.empty() ||
         std::find(device.homing_methods.begin(), device.homing_methods.end(), method) !=
             device.homing_methods.end();
}

void read_homing(const MapReader& m, const DeviceProfile* device, AxisPlan& a) {
  m.check_keys({"method", "offset", "search_velocity", "zero_velocity", "acceleration", "timeout"});
  auto& h = a.spec.homing;
  // 35 (CiA 402: current position is home) unless the device lacks it: then 37, then its first.
  if (device && !supports_method(*device, h.method))
    h.method = supports_method(*device, 37) ? std::int16_t{37} : device->homing_methods.front();
  if (const auto method = m.integer("method", Need::Optional, -128, 127)) {
    if (device && !supports_method(*device, *method))
      m.error("method", "device \"" + device->name + "\" does not support homing method " +
                            std::to_string(*method) + "; supported: " + int_list(device->homing_methods));
    else
      h.method = static_cast<std::int16_t>(*method);
  }
  const NumberRule rate = NumberRule::positive_up_to(kMaxUserValue);
  h.offset = m.number("offset", Need::Optional, NumberRule::range(-kMaxUserValue, kMaxUserValue)).value_or(0.0);
  h.search_velocity = m.number("search_velocity", Need::Optional, rate).value_or(0.0);
  h.zero_velocity = m.number("zero_velocity", Need::Optional, rate).value_or(0.0);
  h.acceleration = m.number("acceleration", Need::Optional, rate).value_or(0.0);
  h.timeout = m.duration("timeout", Need::Optional, 0ns, kMaxTimeout).value_or(h.timeout);
}

}  // namespace

ReadAxis read_axis(const MapReader& axis, AxisContext& ctx) {
  ReadAxis out;
  AxisPlan& a = out.plan;
  std::vector<std::string> keys{"name", "bus", "address", "device", "unit", "mechanics", "limits",
                                "defaults", "homing", "command_timeout", "timeout_stop", "enable_step_timeout"};
  const auto sections = ctx.bus_types.axis_sections();
  keys.insert(keys.end(), sections.begin(), sections.end());
  axis.check_keys(keys);

  a.spec.name = axis.name("name", Need::Required).value_or("");

  const BusTypeInfo* bus_type = nullptr;  // null when the bus or its type is unknown
  if (const auto bus = axis.name("bus", Need::Required)) {
    const auto it = std::find_if(ctx.buses.begin(), ctx.buses.end(), [&](const BusPlan& b) { return b.name == *bus; });
    if (it == ctx.buses.end()) {
      const auto known = bus_names(ctx.buses);
      axis.error("bus", "unknown bus " + in_quotes(*bus) + did_you_mean(*bus, known) + " (buses: " + join(known) + ")");
    } else {
      out.bus = static_cast<std::size_t>(it - ctx.buses.begin());
      bus_type = it->type_info.get();
    }
  }

  const std::int64_t lo = bus_type ? bus_type->min_address : 0;
  const std::int64_t hi = bus_type ? bus_type->max_address : std::numeric_limits<std::int32_t>::max();
  a.address = static_cast<int>(
      axis.integer("address", Need::Required, lo, hi, bus_type ? bus_type->address_words : "an integer").value_or(0));

  const DeviceProfile* device = read_device(axis, ctx);
  if (device) {
    a.device = *device;
    a.spec.device = device->name;
    a.spec.modes = device->modes;
    a.spec.homing_methods = device->homing_methods;
  }
  if (axis.has("unit")) {
    const auto unit = axis.string("unit", Need::Optional);
    if (unit && (unit->empty() || unit->size() > 15))
      axis.error("unit", "must be a unit label of 1 to 15 characters such as mm, deg or rev, got \"" + *unit + "\"");
    else if (unit)
      a.spec.user_unit = *unit;
  }

  read_mechanics(axis.map("mechanics", Need::Optional), device, a);
  const bool scaled = device != nullptr;  // units are known only with the device
  read_limits(axis.map("limits", Need::Optional), a, scaled);
  read_defaults(axis.map("defaults", Need::Optional), device, a);
  read_homing(axis.map("homing", Need::Optional), device, a);

  a.spec.command_timeout = axis.duration("command_timeout", Need::Optional, 0ns, kMaxTimeout).value_or(a.spec.command_timeout);
  static const std::vector<std::string> kStops{"quick_stop", "halt"};
  if (const auto stop = axis.choice("timeout_stop", Need::Optional, kStops))
    a.spec.timeout_stop = *stop == "halt" ? core::TimeoutStop::Halt : core::TimeoutStop::QuickStop;
  a.spec.enable_step_timeout =
      axis.duration("enable_step_timeout", Need::Optional, 0ns, kMaxTimeout).value_or(a.spec.enable_step_timeout);

  for (const auto& section : sections) {
    if (!axis.has(section)) continue;
    if (bus_type && bus_type->axis_section != section)
      axis.error(section, "only allowed for axes on a " + section + " bus; bus is of type " + bus_type->name);
  }
  if (bus_type && bus_type->read_axis) bus_type->read_axis(axis, ctx.buses[*out.bus], device, ctx.base_dir, a);
  return out;
}

}  // namespace drivegate::config
