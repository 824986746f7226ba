#include <gtest/gtest.h>

#include "config/canopen/plan.hpp"
#include "config/ethercat/plan.hpp"
#include "config/sim/plan.hpp"
#include "config/describe.hpp"
#include "config/loader.hpp"
#include "config/profinet/plan.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

using namespace std::chrono_literals;
using test::test_options;

constexpr const char* kValid = R"(
gateway:
  name: cell-1
  dds: { domain: 7, namespace: plant_a }
  log_level: debug
  status_rate_hz: 100
  status_keepalive: 0
buses:
  - name: sim0
    type: sim
    cycle_time: 500us
    priority: 80
    cpu: 0
    options: { acyclic_latency_cycles: 3 }
axes:
  - name: x
    bus: sim0
    address: 1
    device: generic-cia402
    unit: mm
    mechanics: { encoder_counts_per_rev: 131072, gear_ratio: 3, feed: 5, rated_torque: 0 }
    limits: { min_position: -100, max_position: 500, max_velocity: 200, max_acceleration: 2000, max_torque: 150 }
    defaults: { mode: profile_position, velocity: 50, acceleration: 500, deceleration: 400, torque_slope: 10 }
    homing: { method: 35, offset: 1.5, search_velocity: 10, zero_velocity: 2, acceleration: 100, timeout: 20s }
    command_timeout: 250ms
    timeout_stop: halt
    enable_step_timeout: 1.5s
    sim: { start_position: 10, home_switch: 20, negative_limit_switch: -110, positive_limit_switch: 510, max_velocity: 300 }
  - name: table
    bus: sim0
    address: 2
    device: pp-only
    unit: deg
    mechanics: { gear_ratio: 10, feed: 360, rated_torque: 4 }
    defaults: { mode: pp }
)";

TEST(LoadValid, GatewayAndBus) {
  const Plan plan = load_plan_from_string(kValid, "valid.yaml", test_options());
  EXPECT_EQ(plan.file, "valid.yaml");
  EXPECT_EQ(plan.gateway.name, "cell-1");
  EXPECT_EQ(plan.gateway.domain, 7);
  EXPECT_EQ(plan.gateway.ns, "plant_a");
  EXPECT_EQ(plan.gateway.log_level, "debug");
  EXPECT_DOUBLE_EQ(plan.gateway.status_rate_hz, 100.0);
  EXPECT_EQ(plan.gateway.status_keepalive, core::Duration::zero());
  ASSERT_EQ(plan.buses.size(), 1U);
  const BusPlan& bus = plan.buses[0];
  EXPECT_EQ(bus.name, "sim0");
  EXPECT_EQ(bus.type, "sim");
  EXPECT_EQ(bus.cycle_time, core::Duration{500us});
  EXPECT_EQ(bus.priority, 80);
  EXPECT_EQ(bus.cpu, 0);
  EXPECT_EQ(bus.section<SimBusOptions>().acyclic_latency_cycles, 3);
  EXPECT_EQ(std::get<std::int64_t>(bus.options.at("acyclic_latency_cycles")), 3);
  ASSERT_EQ(bus.axes.size(), 2U);
  EXPECT_TRUE(plan.warnings.empty());
}

TEST(LoadValid, AxisSpecIsFilledWithHandComputedFactors) {
  const Plan plan = load_plan_from_string(kValid, "valid.yaml", test_options());
  const AxisPlan& x = plan.buses[0].axes[0];
  const core::AxisSpec& s = x.spec;
  EXPECT_EQ(s.name, "x");
  EXPECT_EQ(x.address, 1);
  EXPECT_EQ(s.device, "generic-cia402");
  EXPECT_EQ(s.user_unit, "mm");
  // 131072 counts/motor rev * 3 motor rev/load rev / 5 mm/load rev = 78643.2 counts per mm.
  EXPECT_DOUBLE_EQ(s.units.position_factor(), 78643.2);
  EXPECT_DOUBLE_EQ(s.units.velocity_factor(), 78643.2);      // counts/s per mm/s
  EXPECT_DOUBLE_EQ(s.units.acceleration_factor(), 78643.2);  // counts/s^2 per mm/s^2
  EXPECT_DOUBLE_EQ(s.units.torque_factor(), 10.0);           // 1000 per mille / 100 %
  EXPECT_DOUBLE_EQ(x.encoder_counts_per_rev, 131072.0);
  EXPECT_DOUBLE_EQ(x.native.position_per_rev, 131072.0);
  EXPECT_TRUE(s.modes.contains(core::Mode::CyclicTorque));
  EXPECT_FALSE(s.modes.contains(core::Mode::Velocity));
  EXPECT_EQ(s.homing_methods.size(), 36U);
  EXPECT_EQ(s.default_mode, core::Mode::ProfilePosition);
  EXPECT_DOUBLE_EQ(s.limits.min_position, -100.0);
  EXPECT_DOUBLE_EQ(s.limits.max_position, 500.0);
  EXPECT_TRUE(s.limits.has_position_limits());
  EXPECT_DOUBLE_EQ(s.limits.max_velocity, 200.0);
  EXPECT_DOUBLE_EQ(s.limits.max_acceleration, 2000.0);
  EXPECT_DOUBLE_EQ(s.limits.max_torque, 150.0);
  EXPECT_DOUBLE_EQ(s.defaults.velocity, 50.0);
  EXPECT_DOUBLE_EQ(s.defaults.acceleration, 500.0);
  EXPECT_DOUBLE_EQ(s.defaults.deceleration, 400.0);
  EXPECT_DOUBLE_EQ(s.defaults.torque_slope, 10.0);
  EXPECT_EQ(s.homing.method, 35);
  EXPECT_DOUBLE_EQ(s.homing.offset, 1.5);
  EXPECT_DOUBLE_EQ(s.homing.search_velocity, 10.0);
  EXPECT_DOUBLE_EQ(s.homing.zero_velocity, 2.0);
  EXPECT_DOUBLE_EQ(s.homing.acceleration, 100.0);
  EXPECT_EQ(s.homing.timeout, core::Duration{20s});
  EXPECT_EQ(s.command_timeout, core::Duration{250ms});
  EXPECT_EQ(s.timeout_stop, core::TimeoutStop::Halt);
  EXPECT_EQ(s.enable_step_timeout, core::Duration{1500ms});
  // Simulated drive settings arrive in drive units.
  EXPECT_DOUBLE_EQ(x.section<SimAxisOptions>().start_position, 786432.0);
  ASSERT_TRUE(x.section<SimAxisOptions>().home_switch_position.has_value());
  EXPECT_DOUBLE_EQ(*x.section<SimAxisOptions>().home_switch_position, 1572864.0);
  EXPECT_DOUBLE_EQ(*x.section<SimAxisOptions>().negative_limit_switch_position, -110 * 78643.2);
  EXPECT_DOUBLE_EQ(*x.section<SimAxisOptions>().positive_limit_switch_position, 510 * 78643.2);
  EXPECT_DOUBLE_EQ(x.section<SimAxisOptions>().max_velocity, 300 * 78643.2);
  EXPECT_DOUBLE_EQ(x.section<SimAxisOptions>().max_acceleration, 1000.0 * 131072.0);  // default: 1000 motor rev/s^2
  ASSERT_EQ(x.device.cyclic_objects.size(), 12U);
  EXPECT_EQ(x.device.cyclic_objects[0], (cia402::ObjectId{0x6040, 0}));
}

TEST(LoadValid, FixedDeviceUnitsAndDefaults) {
  const Plan plan = load_plan_from_string(kValid, "valid.yaml", test_options());
  const AxisPlan& t = plan.buses[0].axes[1];
  // pp-only: 1000 units per motor rev, 60 per rev/s (rpm), acceleration in rpm/s.
  // 10 motor rev per 360 deg: 1000 * 10 / 360 per deg; 60 * 10 / 360 per deg/s.
  EXPECT_DOUBLE_EQ(t.spec.units.position_factor(), 10000.0 / 360.0);
  EXPECT_DOUBLE_EQ(t.spec.units.velocity_factor(), 600.0 / 360.0);
  EXPECT_DOUBLE_EQ(t.spec.units.acceleration_factor(), 600.0 / 360.0);
  EXPECT_DOUBLE_EQ(t.spec.units.torque_factor(), 250.0);  // 1000 per mille / 4 Nm
  EXPECT_DOUBLE_EQ(t.encoder_counts_per_rev, 1000.0);    // no encoder given: the device's revolution
  EXPECT_FALSE(t.spec.limits.has_position_limits());
  EXPECT_DOUBLE_EQ(t.spec.limits.max_velocity, 0.0);
  EXPECT_EQ(t.spec.command_timeout, core::Duration{500ms});
  EXPECT_EQ(t.spec.timeout_stop, core::TimeoutStop::QuickStop);
  EXPECT_EQ(t.spec.homing.method, 35);
  EXPECT_TRUE(t.device.quirk("no_sync_producer"));
  EXPECT_FALSE(t.device.quirk("quick_stop_clears_setpoints"));
  EXPECT_DOUBLE_EQ(t.section<SimAxisOptions>().max_velocity, 50.0 * 60.0);  // default top speed 50 rev/s in rpm
}

TEST(LoadValid, DemoConfigLoads) {
  const Plan plan = load_plan(DRIVEGATE_DEMO_CONFIG);
  EXPECT_TRUE(plan.warnings.empty());
  ASSERT_EQ(plan.buses.size(), 4U);
  const BusPlan& bus = plan.buses[0];
  EXPECT_EQ(bus.type, "sim");
  EXPECT_EQ(bus.cycle_time, core::Duration{1ms});
  ASSERT_GE(bus.axes.size(), 4U);
  const auto find = [&](const std::string& name) -> const AxisPlan& {
    for (const auto& a : bus.axes)
      if (a.spec.name == name) return a;
    throw std::runtime_error("no axis " + name);
  };
  EXPECT_DOUBLE_EQ(find("x").spec.units.position_factor(), 131072.0 / 5.0);
  EXPECT_EQ(find("x").spec.default_mode, core::Mode::ProfilePosition);
  EXPECT_EQ(find("y").spec.user_unit, "mm");
  EXPECT_EQ(find("spindle").spec.user_unit, "rev");
  EXPECT_EQ(find("spindle").spec.default_mode, core::Mode::ProfileVelocity);
  EXPECT_DOUBLE_EQ(find("spindle").spec.units.torque_factor(), 400.0);
  const AxisPlan& table = find("turntable");
  EXPECT_EQ(table.spec.user_unit, "deg");
  EXPECT_DOUBLE_EQ(table.spec.units.position_factor(), 10.0 * 65536.0 / 360.0);
  // The homing method must be one the simulated drive implements.
  const std::vector<std::int16_t> sim_methods{1, 2, 17, 18, 33, 34, 35, 37};
  EXPECT_NE(std::find(sim_methods.begin(), sim_methods.end(), table.spec.homing.method), sim_methods.end());
  EXPECT_TRUE(table.section<SimAxisOptions>().negative_limit_switch_position.has_value());
  EXPECT_TRUE(table.section<SimAxisOptions>().home_switch_position.has_value());

  // The CANopen bus: one simulated drive of each reference type.
  const BusPlan& can = plan.buses[1];
  EXPECT_EQ(can.type, "canopen");
  EXPECT_EQ(can.section<CanopenBusOptions>().transport, CanTransportKind::Simulated);
  ASSERT_EQ(can.axes.size(), 3U);
  EXPECT_EQ(can.axes[0].device.name, "kollmorgen-akd");
  EXPECT_EQ(can.axes[1].device.name, "nord-sk500p");
  EXPECT_EQ(can.axes[2].device.name, "stoeber-sd6");

  // The EtherCAT line: an ESR TrioDrive, an I/O slave and a generic servo, simulated in-process.
  const BusPlan& ec = plan.buses[2];
  EXPECT_EQ(ec.type, "ethercat");
  EXPECT_EQ(ec.section<EthercatBusOptions>().transport, EthercatTransportKind::Simulated);
  ASSERT_EQ(ec.section<EthercatBusOptions>().io.size(), 1U);
  EXPECT_EQ(ec.section<EthercatBusOptions>().io[0].position, 2);
  ASSERT_EQ(ec.axes.size(), 2U);
  EXPECT_EQ(ec.axes[0].device.name, "esr-triodrive");
  EXPECT_EQ(ec.axes[1].device.name, "generic-cia402");
  EXPECT_EQ(ec.axes[1].address, 3);

  // The PROFINET network: two AKDs and an IO device, simulated in-process.
  const BusPlan& pn = plan.buses[3];
  EXPECT_EQ(pn.type, "profinet");
  EXPECT_TRUE(pn.section<ProfinetBusOptions>().simulated);
  EXPECT_EQ(pn.section<ProfinetBusOptions>().io.size(), 1U);
  ASSERT_EQ(pn.axes.size(), 2U);
  EXPECT_EQ(pn.axes[0].device.name, "kollmorgen-akd-profinet");
}

TEST(LoadValid, DescribePlanShowsTheImportantNumbers) {
  const Plan plan = load_plan_from_string(kValid, "valid.yaml", test_options());
  const std::string text = describe_plan(plan);
  EXPECT_NE(text.find("gateway cell-1"), std::string::npos) << text;
  EXPECT_NE(text.find("domain 7, namespace plant_a"), std::string::npos) << text;
  EXPECT_NE(text.find("cycle time:      500us"), std::string::npos) << text;
  EXPECT_NE(text.find("SCHED_FIFO priority 80, CPU 0"), std::string::npos) << text;
  EXPECT_NE(text.find("options:         acyclic_latency_cycles=3"), std::string::npos) << text;
  EXPECT_NE(text.find("axis x"), std::string::npos) << text;
  EXPECT_NE(text.find("78643.2 drive units per mm"), std::string::npos) << text;
  EXPECT_NE(text.find("10 drive units per %"), std::string::npos) << text;
  EXPECT_NE(text.find("250 drive units per Nm"), std::string::npos) << text;
  EXPECT_NE(text.find("pp pv tq hm ip csp csv cst"), std::string::npos) << text;
  EXPECT_NE(text.find("250ms, then halt"), std::string::npos) << text;
  EXPECT_NE(text.find("6040h 6060h 607Ah"), std::string::npos) << text;
}

TEST(LoadValid, BusWithoutAxesIsOnlyAWarning) {
  const Plan plan = load_plan_from_string(R"(gateway:
  name: g
buses:
  - name: a
    type: sim
    cycle_time: 1ms
  - name: empty
    type: sim
    cycle_time: 1ms
axes:
  - { name: x, bus: a, address: 1, device: sim-servo, mechanics: { encoder_counts_per_rev: 1000 } }
)",
                                          "w.yaml", test_options());
  ASSERT_EQ(plan.warnings.size(), 1U);
  EXPECT_NE(plan.warnings[0].find("w.yaml:7:5: buses[1]: bus \"empty\" has no axes"), std::string::npos)
      << plan.warnings[0];
  EXPECT_NE(describe_plan(plan).find("warnings"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::config
