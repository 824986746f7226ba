// Configurations with ethercat buses: the typed bus options, the `io:` list, the per-axis ethercat
// section, multi-axis positions, and every error with its exact message. The registry gets a
// stand-in factory for the ethercat type, so these tests do not depend on the adapter.
#include <gtest/gtest.h>

#include "config/ethercat/axis_section.hpp"
#include "config/ethercat/bus_options.hpp"
#include "config/ethercat/bus_type.hpp"
#include "config/ethercat/plan.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

using namespace std::chrono_literals;
using test::errors_of;

LoadOptions options() {
  LoadOptions o = test::test_options();
  BusTypeInfo t = ethercat_bus_type();
  t.make_bus = [](const BusPlan&) -> std::unique_ptr<core::Bus> { return nullptr; };
  o.bus_types.add(std::move(t));
  return o;
}

const std::string kValid = R"(gateway: { name: cell }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 2ms
    options:
      interface: eth1
      sm_watchdog: 50ms
      distributed_clocks: true
      sync0_shift: 200us
      lost_cycles: 5
      transition_timeout: 5s
      sdo_timeout: 300ms
    io:
      - { name: panel, position: 3, vendor_id: 2, product_code: 0x07D83052, inputs: 2, outputs: 1 }
axes:
  - { name: x, bus: ec0, address: 1, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 }, defaults: { mode: ip } }
  - { name: y, bus: ec0, address: 2, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 }, defaults: { mode: csp } }
)";

TEST(EthercatPlans, OptionsIoSlavesAndAxesAreRead) {
  const Plan p = load_plan_from_string(kValid, "t.yaml", options());
  ASSERT_EQ(p.buses.size(), 1U);
  const auto& b = p.buses[0];
  const auto& c = b.section<EthercatBusOptions>();
  EXPECT_EQ(c.transport, EthercatTransportKind::Raw);
  EXPECT_EQ(c.interface, "eth1");
  EXPECT_EQ(c.sm_watchdog, 50ms);
  EXPECT_TRUE(c.distributed_clocks);
  EXPECT_EQ(c.sync0_shift, 200us);
  EXPECT_EQ(c.lost_cycles, 5);
  EXPECT_EQ(c.transition_timeout, 5s);
  EXPECT_EQ(c.sdo_timeout, 300ms);
  EXPECT_EQ(c.boot_retry, 1s);  // default
  ASSERT_EQ(c.io.size(), 1U);
  EXPECT_EQ(c.io[0].name, "panel");
  EXPECT_EQ(c.io[0].position, 3);
  EXPECT_EQ(c.io[0].vendor_id, 2U);
  EXPECT_EQ(c.io[0].product_code, 0x07D83052U);
  EXPECT_EQ(c.io[0].input_bytes, 2);
  EXPECT_EQ(c.io[0].output_bytes, 1);
  ASSERT_EQ(b.axes.size(), 2U);
  EXPECT_EQ(b.axes[0].section<EthercatAxisSpec>().slave_axis, 0);
  EXPECT_EQ(ethercat_address_key(b.axes[1]), "2");
}

TEST(EthercatPlans, ARawBusNeedsAnInterfaceASimBusDoesNot) {
  const std::string no_interface = R"(gateway: { name: cell }
buses: [{ name: ec0, type: ethercat, cycle_time: 1ms }]
)";
  EXPECT_REPORTED(errors_of(no_interface, options()),
                  "buses[0].options.interface: a raw EtherCAT bus needs the Ethernet interface its line is plugged into");
  const Plan p = load_plan_from_string(R"(gateway: { name: cell }
buses: [{ name: ec0, type: ethercat, cycle_time: 1ms, options: { transport: sim } }]
)",
                                       "t.yaml", options());
  EXPECT_EQ(p.buses[0].section<EthercatBusOptions>().transport, EthercatTransportKind::Simulated);
}

TEST(EthercatPlans, OptionErrorsAreExact) {
  const std::string e = errors_of(R"(gateway: { name: cell }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { interface: "eth 1", sync0_shift: 1ms, sm_watchdog: 150us, boot_retry: 20s }
    io:
      - { name: a, position: 4 }
      - { name: a, position: 4, colour: red }
  - { name: ec1, type: ethercat, cycle_time: 50us, options: { interface: eth2, sm_watchdog: 10050us } }
)",
                                  options());
  EXPECT_REPORTED(e, "buses[0].options.interface: must be a network interface name of 1 to 15 characters such as eth1, got \"eth 1\"");
  EXPECT_REPORTED(e, "buses[0].options.sync0_shift: must be shorter than the bus cycle_time (1ms), got 1ms");
  EXPECT_REPORTED(e, "buses[0].options.sm_watchdog: must be longer than two cycles (2ms) or the slaves drop out between frames, got 150us");
  EXPECT_REPORTED(e, "buses[0].options.boot_retry_max: must not be shorter than boot_retry (20s), got 10s");
  EXPECT_REPORTED(e, "buses[0].io[1].name: I/O slave \"a\" is listed twice");
  EXPECT_REPORTED(e, "buses[0].io[1].position: position 4 is given to two I/O slaves");
  EXPECT_REPORTED(e, "buses[0].io[1].colour: unknown field (allowed: name, position, vendor_id, product_code, inputs, outputs, esi)");
  EXPECT_REPORTED(e, "buses[1].cycle_time: must be a duration in 125us..100ms");
  EXPECT_REPORTED(e, "buses[1].options.sm_watchdog: must be a multiple of 100us (the watchdog counts 100us steps), got 10050us");
}

TEST(EthercatPlans, TheIoKeyBelongsToEthercatBusesOnly) {
  const std::string e = errors_of(R"(gateway: { name: cell }
buses: [{ name: s, type: sim, cycle_time: 1ms, io: [] }]
)",
                                  options());
  EXPECT_REPORTED(e, "buses[0].io: unknown field (allowed: name, type, cycle_time, priority, cpu, options)");
}

TEST(EthercatPlans, AxesOfOneSlaveAreToldApartByTheirAxisIndex) {
  const std::string yaml = R"(gateway: { name: cell }
buses:
  - { name: ec0, type: ethercat, cycle_time: 1ms, options: { transport: sim }, io: [{ name: panel, position: 2 }] }
axes:
  - { name: a, bus: ec0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: b, bus: ec0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: c, bus: ec0, address: 2, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 1 } }
  - { name: d, bus: ec0, address: 3, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 0, colour: red } }
)";
  const std::string e = errors_of(yaml, options());
  EXPECT_REPORTED(e, "axes[1].address: axis \"b\": position 1 on bus \"ec0\" is already used by axes[0].address (axis \"a\")");
  EXPECT_REPORTED(e, "axes[2].ethercat.axis: device \"generic-cia402\" carries 1 axis per slave (0..0), got 1");
  EXPECT_REPORTED(e, "axes[3].ethercat.colour: unknown field (allowed: axis, esi)");
  EXPECT_REPORTED(e, "I/O slave \"panel\" is at position 2, where axis \"c\" is");
}

// Two axes on one two-axis slave, told apart by `ethercat.axis`; an index beyond the profile's
// axes, and a slave axis claimed twice, are refused.
TEST(EthercatPlans, TwoAxesOfATwoAxisSlave) {
  const Plan p = load_plan_from_string(R"(gateway: { name: cell }
buses: [{ name: ec0, type: ethercat, cycle_time: 1ms, options: { transport: sim } }]
axes:
  - { name: l, bus: ec0, address: 1, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: r, bus: ec0, address: 1, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 1 } }
)",
                                       "t.yaml", options());
  ASSERT_EQ(p.buses[0].axes.size(), 2U);
  EXPECT_EQ(p.buses[0].axes[0].section<EthercatAxisSpec>().slave_axis, 0);
  EXPECT_EQ(p.buses[0].axes[1].section<EthercatAxisSpec>().slave_axis, 1);
  EXPECT_EQ(ethercat_address_key(p.buses[0].axes[1]), "1 axis 1");

  const std::string e = errors_of(R"(gateway: { name: cell }
buses: [{ name: ec0, type: ethercat, cycle_time: 1ms, options: { transport: sim } }]
axes:
  - { name: a, bus: ec0, address: 1, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 1 } }
  - { name: b, bus: ec0, address: 1, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 1 } }
  - { name: c, bus: ec0, address: 2, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 2 } }
  - { name: d, bus: ec0, address: 3, device: generic-cia402-2axis, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: e, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 }, ethercat: { axis: 1 } }
)",
                                  options());
  EXPECT_REPORTED(e, "axes[1].address: axis \"b\": position 1 axis 1 on bus \"ec0\" is already used by axes[0].address "
                     "(axis \"a\")");
  EXPECT_REPORTED(e, "axes[2].ethercat.axis: device \"generic-cia402-2axis\" carries 2 axes per slave (0..1), got 2");
  EXPECT_REPORTED(e, "axes[4].ethercat.axis: device \"generic-cia402\" carries 1 axis per slave (0..0), got 1");
  EXPECT_REPORTED(e, "axes \"d\" and \"e\" share the slave at position 3 but name different devices");
}

TEST(EthercatPlans, AnAxisNeedsADeviceWithAnEthercatSection) {
  const std::string e = errors_of(R"(gateway: { name: cell }
buses: [{ name: ec0, type: ethercat, cycle_time: 1ms, options: { transport: sim } }]
axes: [{ name: a, bus: ec0, address: 1, device: kollmorgen-akd }]
)",
                                  options());
  EXPECT_REPORTED(e, "axes[0].device: device profile \"kollmorgen-akd\" has no ethercat section, which an axis on an "
                     "ethercat bus needs");
}

TEST(EthercatPlans, ADcDriveOnABusWithoutDcIsAWarning) {
  const Plan p = load_plan_from_string(R"(gateway: { name: cell }
buses: [{ name: ec0, type: ethercat, cycle_time: 1ms, options: { transport: sim, distributed_clocks: false } }]
axes: [{ name: a, bus: ec0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }]
)",
                                       "t.yaml", options());
  ASSERT_EQ(p.warnings.size(), 1U);
  EXPECT_NE(p.warnings[0].find("device \"generic-cia402\" runs its cyclic modes on SYNC0, but bus \"ec0\" has "
                               "distributed_clocks: false"),
            std::string::npos)
      << p.warnings[0];
}

}  // namespace
}  // namespace drivegate::config
