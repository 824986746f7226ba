#include "config/sim/bus_type.hpp"

#include "config/axis_reader.hpp"
#include "config/sim/plan.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

void read_sim_bus(const MapReader&, const MapReader&, BusPlan& bus) {
  bus.sections.edit<SimBusOptions>().acyclic_latency_cycles =
      static_cast<int>(std::get<std::int64_t>(bus.options.at("acyclic_latency_cycles")));
}

// Positions in user units, stored in drive units; without a device the units are unknown and only
// the checks run.
void read_sim_axis(const MapReader& axis, const BusPlan&, const DeviceProfile* device, const std::filesystem::path&,
                   AxisPlan& a) {
  const MapReader m = axis.map("sim", Need::Optional);
  m.check_keys({"start_position", "home_switch", "negative_limit_switch", "positive_limit_switch", "max_velocity",
                "max_acceleration"});
  const auto& u = a.spec.units;
  auto& s = a.sections.edit<SimAxisOptions>();
  const NumberRule position = NumberRule::range(-kMaxUserValue, kMaxUserValue);
  const NumberRule rate = NumberRule::positive_up_to(kMaxUserValue);
  const auto start = m.number("start_position", Need::Optional, position);
  const auto home = m.number("home_switch", Need::Optional, position);
  const auto neg = m.number("negative_limit_switch", Need::Optional, position);
  const auto pos = m.number("positive_limit_switch", Need::Optional, position);
  const auto vmax = m.number("max_velocity", Need::Optional, rate);
  const auto amax = m.number("max_acceleration", Need::Optional, rate);
  if (neg && pos && *neg >= *pos)
    m.error("negative_limit_switch", "must be less than positive_limit_switch (" + format_number(*pos) +
                                         "), got " + format_number(*neg));
  const auto outside = [&](double v) { return (neg && v <= *neg) || (pos && v >= *pos); };
  if (home && outside(*home)) m.error("home_switch", "must lie between the limit switches");
  if (start && outside(*start)) m.error("start_position", "must lie between the limit switches");
  if (!device) return;
  s.start_position = u.position_to_drive(start.value_or(0.0));
  if (home) s.home_switch_position = u.position_to_drive(*home);
  if (neg) s.negative_limit_switch_position = u.position_to_drive(*neg);
  if (pos) s.positive_limit_switch_position = u.position_to_drive(*pos);
  // Without settings the simulated motor tops out at 50 rev/s (3000 rpm) and 1000 rev/s^2.
  s.max_velocity = vmax ? u.velocity_to_drive(*vmax) : 50.0 * a.native.velocity_per_rps;
  s.max_acceleration = amax ? u.acceleration_to_drive(*amax) : 1000.0 * a.native.acceleration_per_rps2;
}

// The simulated drive's settings are stored in drive units; shown in user units again.
void describe_sim_axis(const BusPlan&, const AxisPlan& a, DescribeRows& rows) {
  const auto& s = a.spec;
  const std::string& u = s.user_unit;
  const auto& sim = a.section<SimAxisOptions>();
  const auto user = [&](const std::optional<double>& drive) {
    return drive ? format_number(s.units.position_to_user(*drive)) + " " + u : std::string{"none"};
  };
  rows.emplace_back("simulated drive", "start " + user(sim.start_position) + ", home switch " +
                                           user(sim.home_switch_position) + ", limit switches " +
                                           user(sim.negative_limit_switch_position) + " / " +
                                           user(sim.positive_limit_switch_position) + ", top speed " +
                                           format_number(s.units.velocity_to_user(sim.max_velocity)) + " " + u + "/s");
}

}  // namespace

BusTypeInfo sim_bus_type() {
  BusTypeInfo t;
  t.name = "sim";
  t.axis_section = "sim";
  t.options.push_back({"acyclic_latency_cycles", OptionKind::Integer, 1, 1000, std::int64_t{1},
                       "cycles before a simulated drive answers an acyclic read/write", {}});
  t.read_bus = read_sim_bus;
  t.read_axis = read_sim_axis;
  t.describe_axis = describe_sim_axis;
  return t;
}

}  // namespace drivegate::config
