#include "adapters/canopen/bus_type.hpp"

#include <stdexcept>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/plan_load.hpp"
#include "adapters/canopen/scan.hpp"
#include "config/canopen/bus_type.hpp"

namespace drivegate::canopen {

namespace {

// What the bus sends per SYNC cycle must fit on the wire at its bit rate, with room to spare for
// SDO, EMCY and retries (estimate: wire/bus_load.hpp, worst-case stuffing).
void check_load(const config::BusPlan& bus, const config::BusEntry& at) {
  if (bus.axes.empty()) return;
  const CycleLoad load = plan_cycle_load(bus);
  const std::string what = "bus load " + describe_cycle_load(bus, load);
  if (load.fraction > 1.0)
    at.source.error(at.mark, at.path, what + ": it cannot fit; lengthen cycle_time, raise the bit rate or map fewer PDOs");
  else if (load.fraction > kCycleLoadWarning)
    at.source.warning(at.mark, at.path, what + ": little room is left for SDO transfers, EMCYs and retries");
  if (load.unbounded > 0)
    at.source.warning(at.mark, at.path,
                      std::to_string(load.unbounded) +
                          " event-driven TPDO(s) without an inhibit time: their rate is bounded only by how often the "
                          "drive's data changes; give them an inhibit_time_100us");
}

void describe_load(const config::BusPlan& bus, config::DescribeRows& rows) {
  if (!bus.axes.empty()) rows.emplace_back("load", describe_cycle_load(bus, plan_cycle_load(bus)));
}

std::unique_ptr<core::Bus> make_bus(const config::BusPlan& plan) {
  try {
    return make_canopen_bus(plan);
  } catch (const TransportError& e) {
    throw core::BusError(e.what());
  } catch (const std::invalid_argument& e) {  // a simulated drive refused its configuration
    throw core::BusError("bus '" + plan.name + "': " + e.what());
  }
}

}  // namespace

config::BusTypeInfo bus_type() {
  config::BusTypeInfo t = config::canopen_bus_type();
  t.check_bus.insert(t.check_bus.begin(), check_load);
  t.describe_bus.push_back(describe_load);
  t.make_bus = make_bus;
  t.scan = {.plan = scan_bus_plan, .run = run_scan};
  return t;
}

}  // namespace drivegate::canopen
