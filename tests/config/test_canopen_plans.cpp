// Configurations with canopen buses: the typed bus options, the per-axis canopen section, EDS
// checks, --check-config output, and every error with its exact message.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "config/canopen/plan.hpp"
#include "config/describe.hpp"
#include "config/canopen/eds.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

using namespace std::chrono_literals;
using test::errors_of;
using test::test_options;
using cia402::ObjectId;

// Relative paths in these configs start at tests/config (the label's directory).
const std::string kLabel = DRIVEGATE_TEST_DEVICE_DIR "/../plan.yaml";

const std::string kValid = R"(gateway: { name: cell }
buses:
  - name: can0
    type: canopen
    cycle_time: 4ms
    priority: 50
    options:
      transport: udp-multicast
      interface: 127.0.0.1
      bitrate: 1000000
      group: 239.1.2.3
      port: 40000
      gateway_node_id: 100
      heartbeat_period: 50ms
      drive_heartbeat: 20ms
      heartbeat_misses: 4
      guard_time: 50ms
      life_time_factor: 5
      sdo_timeout: 250ms
      sdo_retries: 3
      boot_retry: 500ms
      boot_retry_max: 30s
      sync: true
      rpdo_refresh: 0
axes:
  - name: x
    bus: can0
    address: 5
    device: kollmorgen-akd
    unit: mm
    mechanics: { feed: 5 }
    defaults: { mode: csp }
    canopen:
      eds: devices/akd-canopen.eds
      startup_writes: [{ object: "0x36E8", type: u32, value: 0, why: "no SYNC supervision on this axis" }]
  - { name: y, bus: can0, address: 6, device: nord-sk500p, defaults: { mode: vl }, homing: { method: 24 } }
  - name: z
    bus: can0
    address: 7
    device: stoeber-sd6
    mechanics: { encoder_counts_per_rev: 10000 }
    canopen: { sdo_channel: 4, startup_writes: [{ object: A83, type: u8, value: 7, why: node-ID }] }
)";

const AxisPlan& axis(const Plan& plan, const std::string& name) {
  for (const auto& a : plan.buses.at(0).axes)
    if (a.spec.name == name) return a;
  throw std::runtime_error("no axis " + name);
}

TEST(CanopenPlans, BusOptionsAreTyped) {
  const Plan plan = load_plan_from_string(kValid, kLabel, test_options());
  ASSERT_EQ(plan.buses.size(), 1U);
  const BusPlan& b = plan.buses[0];
  EXPECT_EQ(b.type, "canopen");
  EXPECT_EQ(b.cycle_time, core::Duration{4ms});
  const CanopenBusOptions& c = b.section<CanopenBusOptions>();
  EXPECT_EQ(c.transport, CanTransportKind::UdpMulticast);
  EXPECT_EQ(c.interface, "127.0.0.1");
  EXPECT_EQ(c.bitrate, 1000000U);
  EXPECT_EQ(c.group, "239.1.2.3");
  EXPECT_EQ(c.port, 40000);
  EXPECT_EQ(c.gateway_node_id, 100);
  EXPECT_EQ(c.heartbeat_period, core::Duration{50ms});
  EXPECT_EQ(c.drive_heartbeat, core::Duration{20ms});
  EXPECT_EQ(c.heartbeat_misses, 4);
  EXPECT_EQ(c.guard_time, core::Duration{50ms});
  EXPECT_EQ(c.life_time_factor, 5);
  EXPECT_EQ(c.sdo_timeout, core::Duration{250ms});
  EXPECT_EQ(c.sdo_retries, 3);
  EXPECT_EQ(c.boot_retry, core::Duration{500ms});
  EXPECT_EQ(c.boot_retry_max, core::Duration{30s});
  EXPECT_TRUE(c.sync);
  EXPECT_EQ(c.rpdo_refresh, core::Duration::zero());  // every SYNC
  EXPECT_EQ(std::get<std::string>(b.options.at("transport")), "udp-multicast");
  EXPECT_EQ(b.options.size(), 17U);
  EXPECT_TRUE(plan.warnings.empty());
}

TEST(CanopenPlans, DefaultsOfEveryOption) {
  const Plan plan = load_plan_from_string(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms }]
axes: [{ name: x, bus: can0, address: 1, device: kollmorgen-akd }]
)",
                                          "d.yaml", test_options());
  const CanopenBusOptions& c = plan.buses[0].section<CanopenBusOptions>();
  EXPECT_EQ(c.transport, CanTransportKind::SocketCan);
  EXPECT_EQ(c.interface, "can0");
  EXPECT_EQ(std::get<std::string>(plan.buses[0].options.at("interface")), "can0");  // resolved for --check-config
  EXPECT_EQ(c.bitrate, 500000U);
  EXPECT_EQ(c.gateway_node_id, 127);
  EXPECT_EQ(c.heartbeat_period, core::Duration{100ms});
  EXPECT_EQ(c.heartbeat_misses, 3);
  EXPECT_EQ(c.life_time_factor, 3);
  EXPECT_EQ(c.sdo_retries, 2);
  EXPECT_EQ(c.boot_retry, core::Duration{1s});
  EXPECT_EQ(c.boot_retry_max, core::Duration{10s});
  EXPECT_TRUE(c.sync);
  EXPECT_EQ(c.rpdo_refresh, core::Duration{100ms});
  const AxisPlan& x = plan.buses[0].axes[0];
  EXPECT_EQ(x.section<CanopenAxisOptions>().sdo_channel, 1);
  EXPECT_TRUE(x.section<CanopenAxisOptions>().eds.empty());
  EXPECT_TRUE(x.section<CanopenAxisOptions>().eds_objects.empty());
  EXPECT_TRUE(x.section<CanopenAxisOptions>().startup_writes.empty());
  // No encoder resolution needed: the AKD profile fixes 2^20 position units per motor rev.
  EXPECT_DOUBLE_EQ(x.spec.units.position_factor(), 1048576.0);
  const Plan udp = load_plan_from_string(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms, options: { transport: udp-multicast } }]
)",
                                         "d.yaml", test_options());
  EXPECT_EQ(udp.buses[0].section<CanopenBusOptions>().interface, "0.0.0.0");  // any local address
  EXPECT_EQ(udp.buses[0].section<CanopenBusOptions>().group, "239.74.163.2");
  EXPECT_EQ(udp.buses[0].section<CanopenBusOptions>().port, 43113);
}

TEST(CanopenPlans, AxesCarryTheirCanopenSection) {
  const Plan plan = load_plan_from_string(kValid, kLabel, test_options());
  const AxisPlan& x = axis(plan, "x");
  EXPECT_EQ(x.address, 5);
  EXPECT_EQ(x.spec.default_mode, core::Mode::CyclicPosition);
  EXPECT_TRUE(x.device.has_section<CanopenDeviceSpec>());
  EXPECT_EQ(x.device.section<CanopenDeviceSpec>().rpdos.size(), 3U);
  // 2^20 units per motor rev over a 5 mm feed.
  EXPECT_DOUBLE_EQ(x.spec.units.position_factor(), 1048576.0 / 5.0);
  EXPECT_DOUBLE_EQ(x.spec.units.velocity_factor(), 60000.0 / 5.0);
  EXPECT_NE(x.section<CanopenAxisOptions>().eds.find("tests/config/devices/akd-canopen.eds"), std::string::npos) << x.section<CanopenAxisOptions>().eds;
  EXPECT_EQ(x.section<CanopenAxisOptions>().eds.find(".."), std::string::npos) << x.section<CanopenAxisOptions>().eds;
  ASSERT_FALSE(x.section<CanopenAxisOptions>().eds_objects.empty());
  const EdsObject* target = find_eds_object(x.section<CanopenAxisOptions>().eds_objects, "target POSITION");
  ASSERT_NE(target, nullptr);
  EXPECT_EQ(target->id, (ObjectId{0x607A, 0}));
  ASSERT_EQ(x.section<CanopenAxisOptions>().startup_writes.size(), 1U);
  EXPECT_EQ(x.section<CanopenAxisOptions>().startup_writes[0].def.id, (ObjectId{0x36E8, 0}));
  EXPECT_EQ(x.section<CanopenAxisOptions>().startup_writes[0].value, 0);

  const AxisPlan& y = axis(plan, "y");
  EXPECT_EQ(y.spec.default_mode, core::Mode::Velocity);
  EXPECT_EQ(y.spec.homing.method, 24);
  EXPECT_DOUBLE_EQ(y.spec.units.velocity_factor(), 60.0);  // rpm per rev/s
  EXPECT_EQ(y.device.cyclic_objects.size(), 15U);          // derived from NORD's maps

  const AxisPlan& z = axis(plan, "z");
  EXPECT_EQ(z.section<CanopenAxisOptions>().sdo_channel, 4);
  ASSERT_EQ(z.section<CanopenAxisOptions>().startup_writes.size(), 1U);
  EXPECT_EQ(z.section<CanopenAxisOptions>().startup_writes[0].def.id, (ObjectId{0x2053, 0}));  // A83 by the SD6 naming
  EXPECT_EQ(z.device.section<CanopenDeviceSpec>().error_control, ErrorControl::Guarding);
  EXPECT_EQ(gateway_watch_of(z), GatewayWatch::Guarding);
  EXPECT_EQ(gateway_watch_of(x), GatewayWatch::Heartbeat);
}

TEST(CanopenPlans, CheckConfigShowsTheCanopenPlan) {
  const std::string text = describe_plan(load_plan_from_string(kValid, kLabel, test_options()));
  EXPECT_NE(text.find("transport=udp-multicast"), std::string::npos) << text;
  EXPECT_NE(text.find("CAN:             udp-multicast 239.1.2.3:40000 from 127.0.0.1, 1000 kbit/s, gateway node-ID 100"),
            std::string::npos) << text;
  EXPECT_NE(text.find("SYNC:            every 4ms"), std::string::npos) << text;
  // 3 axes (AKD, NORD, SD6) at 1 Mbit/s: the estimate with worst-case stuffing.
  EXPECT_NE(text.find("load:            18 frames, 1969 bits = 1.97 ms per 4 ms SYNC cycle at 1000 kbit/s (49 %)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("node-ID:               5"), std::string::npos) << text;
  EXPECT_NE(text.find("RPDO 1:                sync (type 1): 6040h u16, 6060h i8, 6071h i16 (5 bytes)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("TPDO 3:                event (type 255, inhibit 10ms, timer 100ms): 1002h u32 (4 bytes)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("RPDO 1:                event (type 255): 6040h u16, 6042h i16, 6060h i8 (5 bytes, sent as 8)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("error control:         heartbeat: drive sends every 20ms, lost after 4 silent periods; drive "
                      "watches the gateway's heartbeat (1016h, 200ms)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("error control:         guarding every 50ms, life time factor 5 (drive stops after 250ms"),
            std::string::npos) << text;
  EXPECT_NE(text.find("PDO maps:              verified only (configured in the drive; mapping count fixed at 6)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("start-up write:        36E9h u32 = 789 (0x315) -- FBUS.PARAM05"), std::string::npos) << text;
  EXPECT_NE(text.find("start-up write:        2053h u8 = 7 -- node-ID"), std::string::npos) << text;
  EXPECT_NE(text.find("SDO channel:           4"), std::string::npos) << text;
  EXPECT_NE(text.find("akd-canopen.eds ("), std::string::npos) << text;
}

// A plan whose cyclic traffic does not fit in its SYNC cycle is refused; one that nearly fills it
// gets a warning.
TEST(CanopenPlanErrors, BusLoadMustFitTheCycle) {
  std::string yaml = kValid;
  yaml.replace(yaml.find("cycle_time: 4ms"), 15, "cycle_time: 1ms");
  EXPECT_REPORTED(errors_of(yaml, test_options(), kLabel), "plan.yaml:3:5: buses[0]: bus load 17 frames, 1910 bits = 1.91 ms per 1 ms SYNC "
                                        "cycle at 1000 kbit/s (191 %): it cannot fit; lengthen cycle_time, raise the "
                                        "bit rate or map fewer PDOs");
  yaml.replace(yaml.find("cycle_time: 1ms"), 15, "cycle_time: 4ms");
  yaml.replace(yaml.find("bitrate: 1000000"), 16, "bitrate: 500000");  // 1969 bits = 3.94 ms: 98 %
  const Plan plan = load_plan_from_string(yaml, kLabel, test_options());
  bool warned = false;
  for (const auto& w : plan.warnings) warned = warned || w.find("little room is left") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(CanopenPlans, SimTransportShowsThePersonas) {
  const Plan plan = load_plan_from_string(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim } }]
axes:
  - { name: x, bus: can0, address: 1, device: kollmorgen-akd }
  - { name: y, bus: can0, address: 2, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)",
                                          "s.yaml", test_options());
  EXPECT_EQ(plan.buses[0].section<CanopenBusOptions>().transport, CanTransportKind::Simulated);
  const std::string text = describe_plan(plan);
  EXPECT_NE(text.find("simulated drive:       persona akd"), std::string::npos) << text;
  EXPECT_NE(text.find("simulated drive:       persona generic"), std::string::npos) << text;
}

// A canopen bus (line 3) and one axis whose lines start at 5; tests append axis lines from line 9.
std::string one_axis(const std::string& options, const std::string& device, int node, const std::string& extra = "") {
  return "gateway: { name: g }\nbuses:\n  - { name: can0, type: canopen, cycle_time: 4ms, options: { " + options +
         " } }\naxes:\n  - name: x\n    bus: can0\n    address: " + std::to_string(node) + "\n    device: " + device +
         "\n" + extra;
}

TEST(CanopenPlanErrors, NodeIdRangeNamesCanopen) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms }]
axes:
  - { name: x, bus: can0, address: 0, device: kollmorgen-akd }
  - { name: y, bus: can0, address: 128, device: kollmorgen-akd }
)");
  EXPECT_REPORTED(e, "t.yaml:4:36: axes[0].address: must be a CANopen node-ID in 1..127, got \"0\"");
  EXPECT_REPORTED(e, "t.yaml:5:36: axes[1].address: must be a CANopen node-ID in 1..127, got \"128\"");
}

TEST(CanopenPlanErrors, TwoAxesOnOneNodeId) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms }]
axes:
  - { name: x, bus: can0, address: 5, device: kollmorgen-akd }
  - { name: y, bus: can0, address: 5, device: kollmorgen-akd }
)");
  EXPECT_REPORTED(e, "t.yaml:5:36: axes[1].address: axis \"y\": node-ID 5 on bus \"can0\" is already used by "
                     "axes[0].address (axis \"x\")");
}

TEST(CanopenPlanErrors, GatewayNodeIdCollision) {
  const std::string e = errors_of(one_axis("gateway_node_id: 9", "kollmorgen-akd", 9));
  EXPECT_REPORTED(e, "t.yaml:7:14: axes[0].address: node-ID 9 is the gateway's own on bus \"can0\" (option "
                     "gateway_node_id); give the drive another node-ID or change gateway_node_id");
  const std::string def = errors_of(one_axis("", "kollmorgen-akd", 127));
  EXPECT_REPORTED(def, "axes[0].address: node-ID 127 is the gateway's own");
}

TEST(CanopenPlanErrors, TransportAndNetworkOptions) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: a, type: canopen, cycle_time: 4ms, options: { transport: socketcam, bitrate: 100000 } }
  - { name: b, type: canopen, cycle_time: 4ms, options: { transport: udp-multicast, group: 10.0.0.1, interface: eth0 } }
  - { name: c, type: canopen, cycle_time: 4ms, options: { interface: a-very-long-can-name, bitrate: 2000000 } }
  - { name: d, type: canopen, cycle_time: 4ms, options: { transport: udp-multicast, group: 239.1.300.4 } }
)");
  EXPECT_REPORTED(e, "t.yaml:3:70: buses[0].options.transport: must be one of socketcan, udp-multicast, sim, got "
                     "\"socketcam\", did you mean \"socketcan\"?");
  EXPECT_REPORTED(e, "t.yaml:3:90: buses[0].options.bitrate: must be a CiA 301 bit rate: 10000, 20000, 50000, 125000, "
                     "250000, 500000, 800000 or 1000000 (bit/s), got 100000");
  EXPECT_REPORTED(e, "t.yaml:4:92: buses[1].options.group: must be an IPv4 multicast group (224.0.0.0 to "
                     "239.255.255.255) such as 239.74.163.2, got \"10.0.0.1\"");
  EXPECT_REPORTED(e, "t.yaml:4:113: buses[1].options.interface: with transport udp-multicast, must be the local IPv4 "
                     "address to send from");
  EXPECT_REPORTED(e, "t.yaml:5:70: buses[2].options.interface: must be a CAN network interface name of 1 to 15 "
                     "characters such as can0, got \"a-very-long-can-name\"");
  EXPECT_REPORTED(e, "t.yaml:5:101: buses[2].options.bitrate: must be an integer in 10000..1000000, got \"2000000\"");
  EXPECT_REPORTED(e, "buses[3].options.group: must be an IPv4 multicast group");
}

TEST(CanopenPlanErrors, TimingOptions) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - name: a
    type: canopen
    cycle_time: 500us
    options: { heartbeat_period: 1500us, drive_heartbeat: 0, guard_time: 70s, life_time_factor: 0 }
  - name: b
    type: canopen
    cycle_time: 1000500ns
    options: { heartbeat_period: 30s, heartbeat_misses: 3, boot_retry: 20s, boot_retry_max: 10s, sync: maybe, rpdo_refresh: 11s }
)");
  EXPECT_REPORTED(e, "t.yaml:5:17: buses[0].cycle_time: must be a duration in 1ms..1s");
  EXPECT_REPORTED(e, "t.yaml:6:34: buses[0].options.heartbeat_period: must be whole milliseconds (a heartbeat "
                     "consumer (1016h) counts ms), got 1500us");
  EXPECT_REPORTED(e, "t.yaml:6:59: buses[0].options.drive_heartbeat: must be a duration in 1ms..65535ms");
  EXPECT_REPORTED(e, "t.yaml:6:74: buses[0].options.guard_time: must be a duration in 1ms..65535ms");
  EXPECT_REPORTED(e, "t.yaml:6:97: buses[0].options.life_time_factor: must be an integer in 1..255, got \"0\"");
  EXPECT_REPORTED(e, "t.yaml:9:17: buses[1].cycle_time: must be whole microseconds for a canopen bus (the SYNC "
                     "period, 1006h counts us), got 1000500ns");
  EXPECT_REPORTED(e, "t.yaml:10:57: buses[1].options.heartbeat_misses: heartbeat_period x heartbeat_misses = 90s "
                     "must fit a drive's heartbeat consumer time (1016h: at most 65535ms)");
  EXPECT_REPORTED(e, "t.yaml:10:93: buses[1].options.boot_retry_max: must not be shorter than boot_retry (20s), got 10s");
  EXPECT_REPORTED(e, "t.yaml:10:104: buses[1].options.sync: must be true or false, got \"maybe\"");
  EXPECT_REPORTED(e, "t.yaml:10:125: buses[1].options.rpdo_refresh: must be a duration in 0..10s");
}

TEST(CanopenPlanErrors, UdpOptionsOnOtherTransportsAreWarnings) {
  const Plan plan = load_plan_from_string(one_axis("group: 239.1.1.1, port: 5000", "kollmorgen-akd", 1), "t.yaml",
                                          test_options());
  ASSERT_EQ(plan.warnings.size(), 3U);
  EXPECT_EQ(plan.warnings[0], "t.yaml:3:69: buses[0].options.group: is only used with transport udp-multicast; "
                              "transport is socketcan");
  EXPECT_NE(plan.warnings[1].find("buses[0].options.port: is only used"), std::string::npos) << plan.warnings[1];
  // And, as for any watched bus without real-time priority:
  EXPECT_NE(plan.warnings[2].find("runs without real-time priority"), std::string::npos) << plan.warnings[2];
}

TEST(CanopenPlanErrors, SdoChannels) {
  const std::string sd6 = errors_of(one_axis("", "stoeber-sd6", 40, "    mechanics: { encoder_counts_per_rev: 100 }\n"
                                                                     "    canopen: { sdo_channel: 2 }\n"));
  EXPECT_REPORTED(sd6, "t.yaml:10:29: axes[0].canopen.sdo_channel: SDO channels 2..4 need node-ID <= 31 (their COB-IDs "
                       "580h + 20h x (channel - 1) + node-ID overlap channel 1 above 31); axis node-ID is 40");
  EXPECT_EQ(errors_of(one_axis("", "stoeber-sd6", 31, "    mechanics: { encoder_counts_per_rev: 100 }\n"
                                                      "    canopen: { sdo_channel: 2 }\n")),
            "(loaded without error)");
  const std::string akd = errors_of(one_axis("", "kollmorgen-akd", 5, "    canopen: { sdo_channel: 2, sdo: 1 }\n"));
  EXPECT_REPORTED(akd, "t.yaml:9:29: axes[0].canopen.sdo_channel: device \"kollmorgen-akd\" has 1 SDO channel, got 2");
  EXPECT_REPORTED(akd, "t.yaml:9:32: axes[0].canopen.sdo: unknown field (allowed: eds, "
                       "sdo_channel, startup_writes, gateway_watch)");
}

TEST(CanopenPlanErrors, GatewayWatchIsOneOfFourChoices) {
  const std::string e = errors_of(one_axis("", "generic-cia402", 5, "    mechanics: { encoder_counts_per_rev: 100 }\n"
                                                                  "    canopen: { gateway_watch: always }\n"));
  EXPECT_REPORTED(e, "t.yaml:10:31: axes[0].canopen.gateway_watch: must be one of heartbeat, guarding, required, "
                     "optional, got \"always\"");
  for (const char* v : {"heartbeat", "guarding", "required", "optional"}) {
    const Plan plan = load_plan_from_string(
        one_axis("", "generic-cia402", 5,
                 std::string("    mechanics: { encoder_counts_per_rev: 100 }\n    canopen: { gateway_watch: ") + v +
                     " }\n"),
        "t.yaml", test_options());
    ASSERT_TRUE(plan.buses[0].axes[0].section<CanopenAxisOptions>().gateway_watch.has_value()) << v;
  }
  // Defaults: the profile's (generic-cia402: optional; AKD: heartbeat; SD6: guarding).
  const Plan plan = load_plan_from_string(one_axis("", "generic-cia402", 5,
                                                   "    mechanics: { encoder_counts_per_rev: 100 }\n"),
                                          "t.yaml", test_options());
  EXPECT_EQ(gateway_watch_of(plan.buses[0].axes[0]), GatewayWatch::Optional);
}

TEST(CanopenPlanErrors, ModesAndHomingTheDeviceLacks) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms }]
axes:
  - { name: x, bus: can0, address: 1, device: nord-sk500p, defaults: { mode: csp } }
  - { name: y, bus: can0, address: 2, device: kollmorgen-akd, defaults: { mode: vl } }
  - { name: z, bus: can0, address: 3, device: nord-sk500p, homing: { method: 37 } }
  - { name: w, bus: can0, address: 4, device: kollmorgen-akd, homing: { method: 19 } }
)");
  EXPECT_REPORTED(e, "t.yaml:4:78: axes[0].defaults.mode: device \"nord-sk500p\" does not support mode csp; "
                     "supported: pp, pv, vl, tq, hm");
  EXPECT_REPORTED(e, "t.yaml:5:81: axes[1].defaults.mode: device \"kollmorgen-akd\" does not support mode vl; "
                     "supported: pp, pv, tq, hm, ip, csp");
  EXPECT_REPORTED(e, "t.yaml:6:78: axes[2].homing.method: device \"nord-sk500p\" does not support homing method 37; "
                     "supported: 1, 2, 3");
  EXPECT_REPORTED(e, "t.yaml:7:81: axes[3].homing.method: device \"kollmorgen-akd\" does not support homing method 19; "
                     "supported: -7, -6, -5, -4, -3, 1, 2, 8, 12, 17, 18, 24, 28, 33, 34, 35");
}

TEST(CanopenPlanErrors, DeviceWithoutCanopenSection) {
  const std::string e = errors_of(one_axis("", "sim-servo", 3, "    mechanics: { encoder_counts_per_rev: 4096 }\n"
                                                               "    canopen: { sdo_channel: 1 }\n"));
  EXPECT_REPORTED(e, "t.yaml:8:13: axes[0].device: device profile \"sim-servo\" has no canopen section, which an axis "
                     "on a canopen bus needs (profiles/devices/README.md)");
}

TEST(CanopenPlanErrors, CanopenSectionOnlyOnCanopenBuses) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses: [{ name: sim0, type: sim, cycle_time: 1ms }]
axes:
  - { name: x, bus: sim0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 },
      canopen: { sdo_channel: 1 } }
)");
  EXPECT_REPORTED(e, "t.yaml:5:16: axes[0].canopen: only allowed for axes on a canopen bus; bus is of type sim");
}

TEST(CanopenPlanErrors, SyncOffWithSynchronousPdos) {
  const std::string e = errors_of(one_axis("sync: false", "kollmorgen-akd", 1));
  EXPECT_REPORTED(e, "t.yaml:8:13: axes[0].device: device \"kollmorgen-akd\" maps synchronous PDOs (RPDO 1, "
                     "transmission type 1) but bus \"can0\" has sync: false");
}

TEST(CanopenPlanErrors, SyncPeriodTheDeviceLacks) {
  std::string yaml = one_axis("", "stoeber-sd6", 1, "    mechanics: { encoder_counts_per_rev: 100 }\n");
  yaml.replace(yaml.find("cycle_time: 4ms"), 15, "cycle_time: 3ms");
  const std::string e = errors_of(yaml);
  EXPECT_REPORTED(e, "t.yaml:6:10: axes[0].bus: bus \"can0\" cycle_time 3ms is not a SYNC period device \"stoeber-sd6\" "
                     "supports (1ms, 2ms, 4ms, 8ms)");
}

TEST(CanopenPlanErrors, AxisStartupWrites) {
  const std::string e = errors_of(one_axis("", "stoeber-sd6", 1, R"(    mechanics: { encoder_counts_per_rev: 100 }
    canopen:
      startup_writes:
        - { object: A540, type: i16, value: 2, why: fault reaction }
        - { object: "0x6060", type: i8, value: 1, why: mode }
        - { object: "0x6060", type: i8, value: 3, why: mode again }
)"));
  EXPECT_REPORTED(e, "t.yaml:12:21: axes[0].canopen.startup_writes[0].object: line 540 is beyond 511");
  EXPECT_REPORTED(e, "t.yaml:14:21: axes[0].canopen.startup_writes[2].object: 0x6060 is already written by "
                     "axes[0].canopen.startup_writes[1]");
}

TEST(CanopenPlanErrors, EdsMismatch) {
  const std::string e = errors_of(one_axis("", "kollmorgen-akd", 1,
                                           "    canopen:\n      eds: devices/akd-broken.eds\n"
                                           "      startup_writes: [{ object: \"0x6098\", type: i8, value: 35, why: x }]\n"),
                                  test_options(), kLabel);
  const std::string at = kLabel + ":10:12: axes[0].canopen.eds: ";
  EXPECT_REPORTED(e, at + "device \"kollmorgen-akd\" maps 6071h in RPDO 1, which EDS \"akd-broken.eds\" does not list");
  EXPECT_REPORTED(e, at + "device \"kollmorgen-akd\" maps 6060h in RPDO 1, as i8 (8 bits); EDS \"akd-broken.eds\" has "
                          "INTEGER16 (16 bits, line");
  EXPECT_REPORTED(e, at + "device \"kollmorgen-akd\" maps 6077h in TPDO 1, which EDS \"akd-broken.eds\" marks "
                          "PDOMapping=0 (line");
  EXPECT_REPORTED(e, at + "device \"kollmorgen-akd\" start-up write of 605Ah names an object that is ro in EDS "
                          "\"akd-broken.eds\" (line");
  // 6098h is in the EDS and writable; the whole matching EDS passes.
  EXPECT_EQ(e.find("6098h"), std::string::npos) << e;
  EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 3) << e;
  EXPECT_EQ(errors_of(one_axis("", "kollmorgen-akd", 1, "    canopen: { eds: devices/akd-canopen.eds }\n"), test_options(),
                      kLabel),
            "(loaded without error)");
}

TEST(CanopenPlanErrors, EdsDirectionAndAxisWrites) {
  // 6041h (ro) is only a problem in an RPDO; 6040h (rww) only in a TPDO: generic-cia402 maps them right,
  // so the only problems are its objects the AKD-like EDS lacks and the axis write to a read-only object.
  const std::string e = errors_of(one_axis("", "generic-cia402", 1,
                                           "    mechanics: { encoder_counts_per_rev: 4096 }\n"
                                           "    canopen:\n      eds: devices/akd-canopen.eds\n"
                                           "      startup_writes: [{ object: \"0x6041\", type: u16, value: 0, why: x }]\n"),
                                  test_options(), kLabel);
  EXPECT_REPORTED(e, "device \"generic-cia402\" maps 603Fh in TPDO 1, which EDS \"akd-canopen.eds\" does not list");
  EXPECT_REPORTED(e, "axis start-up write of 6041h names an object that is ro in EDS \"akd-canopen.eds\"");
}

class CanopenEdsFiles : public test::TempDir {};

TEST_F(CanopenEdsFiles, MissingAndBrokenEds) {
  write("bad.eds", "[6040]\nParameterName=Controlword\nDataType=UNSIGNED16\nAccessType=rw\n");
  const std::string label = (dir_ / "plan.yaml").string();
  const std::string e = errors_of(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms }]
axes:
  - { name: x, bus: can0, address: 1, device: kollmorgen-akd, canopen: { eds: nowhere.eds } }
  - { name: y, bus: can0, address: 2, device: kollmorgen-akd, canopen: { eds: bad.eds } }
)",
                                  test_options(), label);
  EXPECT_REPORTED(e, label + ":4:79: axes[0].canopen.eds: file \"" + (dir_ / "nowhere.eds").string() +
                         "\" does not exist (relative paths start at the config file's directory)");
  EXPECT_REPORTED(e, label + ":5:79: axes[1].canopen.eds: EDS \"" + (dir_ / "bad.eds").string() +
                         "\" has errors, listed with its file name");
  EXPECT_REPORTED(e, (dir_ / "bad.eds").string() + ":3:1: [6040].DataType: must be a CiA 301 data type");
}

std::string akd_eds() {
  std::ifstream in(DRIVEGATE_TEST_DEVICE_DIR "/akd-canopen.eds");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

int line_at(const std::string& text, std::size_t pos) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

// What an EDS deviates in is a warning of the plan, so --check-config shows it; two axes with the
// same EDS show it once.
TEST_F(CanopenEdsFiles, EdsWarningsReachThePlan) {
  const std::string akd = akd_eds() + "\n[2FFF]\nParameterName=Vendor thing\nDataType=0x0040\nAccessType=rw\n";
  write("drive.eds", akd + "PDOMapping=yes\n");
  const Plan plan = load_plan_from_string(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms }]
axes:
  - { name: x, bus: can0, address: 1, device: kollmorgen-akd, canopen: { eds: drive.eds } }
  - { name: y, bus: can0, address: 2, device: kollmorgen-akd, canopen: { eds: drive.eds } }
)",
                                          (dir_ / "plan.yaml").string(), test_options());
  const std::string warning = (dir_ / "drive.eds").string() + ":" + std::to_string(line_at(akd, akd.size())) +
                              ":1: [2FFF].PDOMapping: should be 0 or 1, got \"yes\"; read as 1 (mappable)";
  EXPECT_EQ(std::count(plan.warnings.begin(), plan.warnings.end(), warning), 1) << testing::PrintToString(plan.warnings);
  EXPECT_NE(describe_plan(plan).find("warnings\n  " + warning + "\n"), std::string::npos) << describe_plan(plan);
  const EdsObject* vendor = find_eds_object(plan.buses[0].axes[0].section<CanopenAxisOptions>().eds_objects, "vendor thing");
  ASSERT_NE(vendor, nullptr);
  EXPECT_EQ(eds_type_name(vendor->data_type), "0x0040 (vendor-defined)");
}

// An object the device maps but the EDS had to skip: the error says why, since a refused load shows
// no warnings.
TEST_F(CanopenEdsFiles, SkippedObjectIsExplainedInTheError) {
  std::string akd = akd_eds();
  const std::size_t section = akd.find("[6071]");
  const std::size_t type = akd.find("DataType=0x0003", section);
  ASSERT_NE(type, std::string::npos);
  akd.replace(type, 15, "DataType=INT16");
  write("drive.eds", akd);
  const std::string e = errors_of(R"(gateway: { name: g }
buses: [{ name: can0, type: canopen, cycle_time: 4ms }]
axes:
  - { name: x, bus: can0, address: 1, device: kollmorgen-akd, canopen: { eds: drive.eds } }
)",
                                  test_options(), (dir_ / "plan.yaml").string());
  EXPECT_REPORTED(e, "device \"kollmorgen-akd\" maps 6071h in RPDO 1, which EDS \"drive.eds\" does not list (its "
                     "section at line " + std::to_string(line_at(akd, section)) +
                         " was skipped: DataType \"INT16\" is not a data type code)");
}

// Drives that watch the gateway fault when its cycle stalls: --check-config says so for a real bus
// without real-time priority, not for one with it, nor for simulated drives.
TEST(CanopenPlans, WatchedBusWithoutRealtimePriorityIsWarnedAbout) {
  const auto plan_with = [](const std::string& priority, const std::string& transport) {
    return load_plan_from_string("gateway: { name: g }\nbuses:\n  - { name: can0, type: canopen, cycle_time: 4ms, " +
                                     priority + "options: { transport: " + transport +
                                     ", interface: can0 } }\naxes:\n  - { name: akd, bus: can0, address: 1, "
                                     "device: kollmorgen-akd, unit: mm, mechanics: { feed: 5 } }\n",
                                 kLabel, test_options());
  };
  const auto warned = [](const Plan& p) {
    for (const auto& w : p.warnings)
      if (w.find("runs without real-time priority, but its drives watch the gateway") != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(warned(plan_with("", "socketcan")));
  EXPECT_FALSE(warned(plan_with("priority: 60, ", "socketcan")));
  EXPECT_FALSE(warned(plan_with("", "sim")));
}

}  // namespace
}  // namespace drivegate::config
