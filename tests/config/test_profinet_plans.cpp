// Configurations with profinet buses: the typed bus options, the stations (`devices:`), the
// generic IO devices (`io:`), the per-axis profinet section of PROFIdrive drives, the plan
// printout, and every refusal with its exact message. The registry is the build's own, so the
// NameOfStation and C_SDU rules are those of adapters/profinet/wire.
#include <gtest/gtest.h>
#include <unistd.h>

#include <tuple>

#include "config/describe.hpp"
#include "config/profinet/plan.hpp"
#include "core/bus.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

using namespace std::chrono_literals;
using test::errors_of;

const std::string kHead = R"(gateway: { name: cell }
buses:
  - name: pn0
    type: profinet
    cycle_time: 1ms
    options: { interface: eth1, reduction_ratio: 16, ip_assignment: permanent, controller_station: plc-gw }
    devices:
      - { station: akd-x, ip: 192.168.0.10, gateway: 192.168.0.1 }
      - { station: akd-y, ip: 192.168.0.11, netmask: 255.255.0.0, vendor_id: 0x0FEE, device_id: 0x0042 }
      - { station: io-block, ip: 192.168.0.20 }
)";

const std::string kIo = R"(    io:
      - name: panel
        station: io-block
        dap_ident: 0x100
        slots:
          - { slot: 1, module_ident: 0x210, submodule_ident: 0x11, inputs: 2 }
          - { slot: 2, subslot: 1, module_ident: 0x220, submodule_ident: 0x12, outputs: 1 }
        records:
          - { slot: 1, index: 0x100, data: "01 02 ff" }
)";

const std::string kAxes = R"(axes:
  - { name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, profinet: { station: akd-x, telegram: 9 } }
  - { name: y, bus: pn0, address: 2, device: kollmorgen-akd-profinet, profinet: { station: akd-y, telegram: 1 } }
)";

const std::string kValid = kHead + kIo + kAxes;

// The first axis line of kAxes with `x` replaced (its profinet section and the rest of the line).
std::string with_axis_x(const std::string& line) {
  return kHead + kIo + "axes:\n  - " + line + "\n" +
         "  - { name: y, bus: pn0, address: 2, device: kollmorgen-akd-profinet, profinet: { station: akd-y, telegram: 1 } }\n";
}

TEST(ProfinetPlans, OptionsStationsIoDevicesAndAxesAreRead) {
  const Plan p = load_plan_from_string(kValid, "t.yaml", test::test_options());
  ASSERT_EQ(p.buses.size(), 1U);
  const auto& b = p.buses[0];
  const auto& c = b.section<ProfinetBusOptions>();
  EXPECT_EQ(c.interface, "eth1");
  EXPECT_EQ(c.send_clock, 1ms);
  EXPECT_EQ(c.reduction_ratio, 16);
  EXPECT_EQ(c.update_time(), 16ms);
  EXPECT_EQ(c.data_hold_factor, 3);  // default
  EXPECT_EQ(c.data_hold_time(), 48ms);
  EXPECT_EQ(c.dcp_timeout, 3s);       // default
  EXPECT_EQ(c.ip_assignment, ProfinetIpAssignment::Permanent);
  EXPECT_EQ(c.controller_station, "plc-gw");
  ASSERT_EQ(c.stations.size(), 3U);
  EXPECT_EQ(c.stations[0].ip, 0xC0A8000AU);
  EXPECT_EQ(c.stations[0].netmask, 0xFFFFFF00U);  // default
  EXPECT_EQ(c.stations[0].gateway, 0xC0A80001U);
  EXPECT_EQ(c.stations[1].netmask, 0xFFFF0000U);
  EXPECT_EQ(c.stations[1].vendor_id, 0x0FEEU);
  EXPECT_EQ(c.stations[1].device_id, 0x0042U);
  EXPECT_FALSE(c.stations[2].vendor_id.has_value());
  ASSERT_EQ(c.io.size(), 1U);
  const auto& io = c.io[0];
  EXPECT_EQ(io.station, "io-block");
  EXPECT_EQ(io.dap_ident, 0x100U);
  ASSERT_EQ(io.submodules.size(), 2U);
  EXPECT_EQ(io.submodules[0].module_ident, 0x210U);
  EXPECT_EQ(io.submodules[0].input_bytes, 2);
  EXPECT_EQ(io.submodules[1].slot, 2);
  EXPECT_EQ(io.submodules[1].output_bytes, 1);
  ASSERT_EQ(io.records.size(), 1U);
  EXPECT_EQ(io.records[0].index, 0x100U);
  EXPECT_EQ(io.records[0].data, (std::vector<std::uint8_t>{0x01, 0x02, 0xFF}));

  ASSERT_EQ(b.axes.size(), 2U);
  const auto& x = b.axes[0];
  EXPECT_EQ(x.section<ProfinetAxisSpec>().station, "akd-x");
  EXPECT_EQ(x.section<ProfinetAxisSpec>().telegram, 9U);
  EXPECT_EQ(x.section<ProfinetAxisSpec>().slot, 1);
  EXPECT_EQ(x.section<ProfinetAxisSpec>().subslot, 1);
  // Telegram 9 (MDI): moves, real-time jog, homing and program mode; telegram 1: speed mode only.
  EXPECT_TRUE(x.spec.modes.contains(core::Mode::ProfilePosition));
  EXPECT_TRUE(x.spec.modes.contains(core::Mode::ProfileVelocity));
  EXPECT_TRUE(x.spec.modes.contains(core::Mode::Homing));
  EXPECT_TRUE(x.spec.modes.contains(core::Mode::TraversingBlock));
  const auto& y = b.axes[1];
  EXPECT_TRUE(y.spec.modes.contains(core::Mode::ProfileVelocity));
  EXPECT_FALSE(y.spec.modes.contains(core::Mode::ProfilePosition));
  EXPECT_FALSE(y.spec.modes.contains(core::Mode::Homing));
  // The default homing method of a PROFIdrive axis is what the master takes on every telegram.
  EXPECT_EQ(x.spec.homing.method, 0);
  // Native units are the PROFIdrive master's (profiles/profidrive/README.md "Units").
  EXPECT_DOUBLE_EQ(x.native.position_per_rev, 65536.0);
  EXPECT_DOUBLE_EQ(x.native.velocity_per_rps, 10737418.24);
  EXPECT_TRUE(p.warnings.empty()) << p.warnings.front();
}

TEST(ProfinetPlans, ThePlanPrintsStationsArsAndTelegrams) {
  // Rows as "key: value", whatever the printout's column width.
  std::string out = describe_plan(load_plan_from_string(kValid, "t.yaml", test::test_options()));
  for (auto at = out.find(":  "); at != std::string::npos; at = out.find(":  ", at)) out.erase(at + 1, 1);
  for (const char* row : {
           "type: profinet",
           "update time: 1ms send clock x reduction ratio 16 = 16ms, RT class 1, data hold 48ms",
           "controller: station plc-gw on eth1, IP suites set permanent, DCP identify timeout 3s",
           "station: akd-x 192.168.0.10/24 gateway 192.168.0.1",
           "station: akd-y 192.168.0.11/16, vendor 0x0FEE, device 0x0042",
           // Telegram 9: 10 actual octets + IOPS and the DAP's IOPS, the IOCS for the setpoints; 20
           // setpoint octets + IOPS and two IOCS. Both padded to the 40 octet minimum.
           "ar: akd-x: input IOCR frame 0xC000 C_SDU 40 octets (13 used), output IOCR frame 0xC001 C_SDU 40 "
           "octets (23 used), every 1ms x 16 = 16ms, watchdog 3 x 16ms = 48ms",
           "ar: akd-y: input IOCR frame 0xC002 C_SDU 40 octets (7 used), output IOCR frame 0xC003 C_SDU 40 octets (7 used)",
           // DAP IOPS, 2 input octets and IOPS, the IOCS for the outputs; 1 output octet and IOPS, two IOCS.
           "ar: io-block: input IOCR frame 0xC004 C_SDU 40 octets (5 used), output IOCR frame 0xC005 C_SDU 40 octets (4 used)",
           "io: panel at io-block: DAP 0x00000100, slots 1/1 module 0x00000210 submodule 0x00000011 in 2 out 0, "
           "2/1 module 0x00000220 submodule 0x00000012 in 0 out 1, 1 record writes",
           "station: akd-x (192.168.0.10), telegram 9 in slot 1 subslot 1",
           "setpoint words: 10: STW1 w1, SATZANW w2, STW2 w3, MDI_TARPOS w4-5, MDI_VELOCITY w6-7, MDI_ACC w8, MDI_DEC w9, "
           "MDI_MOD w10",
           "actual words: 5: ZSW1 w1, AKTSATZ w2, ZSW2 w3, XIST_A w4-5",
           "setpoint words: 2: STW1 w1, NSOLL_A w2",
       })
    EXPECT_NE(out.find(row), std::string::npos) << row << "\n" << out;
}

TEST(ProfinetPlans, TheFactoryMakesTheBusAndOpenNamesAMissingInterface) {
  std::string text = kValid;
  text.replace(text.find("interface: eth1"), 15, "interface: pn-missing0");
  const Plan p = load_plan_from_string(text, "t.yaml", test::test_options());
  ASSERT_TRUE(p.buses[0].type_info && p.buses[0].type_info->make_bus);
  const std::unique_ptr<core::Bus> bus = p.buses[0].type_info->make_bus(p.buses[0]);
  ASSERT_TRUE(bus);
  EXPECT_EQ(bus->type(), "profinet");
  EXPECT_EQ(bus->axis_count(), 2U);
  EXPECT_EQ(bus->io_count(), 1U);
  EXPECT_EQ(bus->io_info(0).name, "panel");
  if (::geteuid() != 0) GTEST_SKIP() << "the raw socket needs root before the interface is looked at";
  try {
    bus->open(core::TimePoint{});
    FAIL() << "opened a bus on a missing interface";
  } catch (const core::BusError& e) {
    EXPECT_NE(std::string(e.what()).find("bus 'pn0': profinet: no network interface 'pn-missing0'"), std::string::npos)
        << e.what();
  }
}

TEST(ProfinetPlans, AnUpdateTimeBelowTheDevicesMinimumIsRefused) {
  std::string text = kValid;
  text.replace(text.find("reduction_ratio: 16"), 19, "reduction_ratio: 8");
  EXPECT_REPORTED(errors_of(text), "t.yaml:21:21: axes[0].bus: bus \"pn0\" updates the IO data every 8ms (cycle_time 1ms x "
                                   "reduction_ratio 8); device \"kollmorgen-akd-profinet\" needs at least 16ms: raise reduction_ratio");
}

TEST(ProfinetPlans, ATelegramTheDeviceLacksIsRefused) {
  const std::string e = errors_of(with_axis_x(
      "{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, profinet: { station: akd-x, telegram: 2 } }"));
  EXPECT_REPORTED(e, "t.yaml:21:109: axes[0].profinet.telegram: device \"kollmorgen-akd-profinet\" offers telegrams 0, 1, 7, "
                     "9, 350, 351, 352, 353, 400, got 2");
  EXPECT_REPORTED(errors_of(with_axis_x("{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, profinet: "
                                        "{ station: akd-x, telegram: 0 } }")),
                  "axes[0].profinet.telegram: telegram 0's size is set by the module in the drive, which the configuration "
                  "cannot give; use 400 for a free mapping");
}

TEST(ProfinetPlans, StationsAndAddressesMustBeUnique) {
  std::string text = kValid;
  text.replace(text.find("akd-y, ip: 192.168.0.11"), 23, "akd-x, ip: 192.168.0.10");
  const std::string e = errors_of(text);
  EXPECT_REPORTED(e, "t.yaml:9:20: buses[0].devices[1].station: station \"akd-x\" is already listed at buses[0].devices[0]: "
                     "every device needs a name of its own");
  EXPECT_REPORTED(e, "t.yaml:9:31: buses[0].devices[1].ip: IP address 192.168.0.10 is already given to buses[0].devices[0]");
}

TEST(ProfinetPlans, AnAxisNamingAnUnknownStationIsRefused) {
  EXPECT_REPORTED(errors_of(with_axis_x("{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, profinet: "
                                        "{ station: akd-z, telegram: 9 } }")),
                  "t.yaml:21:92: axes[0].profinet.station: unknown station \"akd-z\", did you mean \"akd-x\"? (bus \"pn0\" "
                  "lists: akd-x, akd-y, io-block)");
}

TEST(ProfinetPlans, StationNamesMustKeepTheNameOfStationRules) {
  std::string text = kValid;
  text.replace(text.find("station: akd-x, ip"), 14, "station: AKD-X");
  EXPECT_REPORTED(errors_of(text), "t.yaml:8:20: buses[0].devices[0].station: must be a PROFINET NameOfStation (lower case DNS "
                                   "labels such as akd-x1), got \"AKD-X\": ");
  text = kValid;
  text.replace(text.find("station: akd-x, ip"), 14, "station: port-001");
  EXPECT_REPORTED(errors_of(text), "buses[0].devices[0].station: must be a PROFINET NameOfStation");
  text = kValid;
  text.replace(text.find("controller_station: plc-gw"), 26, "controller_station: -gw");
  EXPECT_REPORTED(errors_of(text), "buses[0].options.controller_station: must be a PROFINET NameOfStation (lower case DNS "
                                   "labels such as akd-x1), got \"-gw\"");
}

TEST(ProfinetPlans, HomingMustBeWhatTheTelegramCanDo) {
  const std::string e = errors_of(with_axis_x(
      "{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, homing: { method: 4, offset: 2 }, profinet: "
      "{ station: akd-x, telegram: 9 } }"));
  EXPECT_REPORTED(e, "axes[0].homing.method: telegram 9 carries no HOME_MODE: the drive homes with the HOME.MODE set in "
                     "it, so homing.method must be 0 (telegram 353 sends the method), got 4");
  EXPECT_REPORTED(e, "axes[0].homing.offset: telegram 9 carries no HOME_DIST: set HOME.DIST in the drive and "
                     "homing.offset to 0 (telegrams 352 and 353 send it), got 2");
  // A CiA 402 method the drive lacks is refused as on every bus.
  EXPECT_REPORTED(errors_of(with_axis_x("{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, homing: "
                                        "{ method: 35 }, profinet: { station: akd-x, telegram: 353 } }")),
                  "axes[0].homing.method: device \"kollmorgen-akd-profinet\" does not support homing method 35");
  const Plan p = load_plan_from_string(with_axis_x("{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, "
                                                   "homing: { method: 4, offset: 2 }, profinet: { station: akd-x, telegram: 353 } }"),
                                       "t.yaml", test::test_options());
  EXPECT_EQ(p.buses[0].axes[0].spec.homing.method, 4);
}

TEST(ProfinetPlans, TheDefaultModeMustBeOneTheTelegramCarries) {
  EXPECT_REPORTED(errors_of(with_axis_x("{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, defaults: "
                                        "{ mode: pp }, profinet: { station: akd-x, telegram: 1 } }")),
                  "axes[0].defaults.mode: mode pp is not possible with telegram 1 (speed mode); choose another telegram or mode");
}

TEST(ProfinetPlans, AStationServesOneAxisOrOneIoDevice) {
  EXPECT_REPORTED(errors_of(with_axis_x("{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet, profinet: "
                                        "{ station: io-block, telegram: 9 } }")),
                  "t.yaml:3:5: buses[0]: station \"io-block\" is used by axis \"x\" and by IO device \"panel\": one station "
                  "is one axis or one IO device");
  const Plan p = load_plan_from_string(kHead + kAxes, "t.yaml", test::test_options());
  ASSERT_EQ(p.warnings.size(), 1U);
  EXPECT_EQ(p.warnings[0], "t.yaml:3:5: buses[0].devices: station \"io-block\" is used by no axis and no IO device; it is not connected");
}

TEST(ProfinetPlans, AnIoLayoutThatDoesNotFitAFrameIsRefused) {
  std::string text = kValid;
  text.replace(text.find("inputs: 2 }"), 11, "inputs: 1440 }");
  EXPECT_REPORTED(errors_of(text), "t.yaml:16:11: buses[0].io[0].slots: the submodules do not fit one RT frame: input frame: the IO data "
                                   "objects need more than 1440 octets (the largest C_SDU)");
}

TEST(ProfinetPlans, IoDevicesAreChecked) {
  const std::string e = errors_of(kHead + R"(    io:
      - name: panel
        station: io-blok
        slots:
          - { slot: 0, module_ident: 1, submodule_ident: 1 }
          - { slot: 1, module_ident: 1, submodule_ident: 1, inputs: 1 }
          - { slot: 1, module_ident: 2, submodule_ident: 1, outputs: 1 }
          - { slot: 2, module: DI_16 }
        records:
          - { slot: 3, index: 0x8000, data: "1" }
          - { slot: 1, index: 1, data: "zz" }
)" + kAxes);
  EXPECT_REPORTED(e, "buses[0].io[0].station: unknown station \"io-blok\", did you mean \"io-block\"?");
  EXPECT_REPORTED(e, "buses[0].io[0].dap_ident: missing");
  EXPECT_REPORTED(e, "buses[0].io[0].slots[0].slot: must be a slot number (1..32767; 0 is the DAP) in 1..32767, got \"0\"");
  EXPECT_REPORTED(e, "buses[0].io[0].slots[2].slot: slot 1 subslot 1 is given twice");
  EXPECT_REPORTED(e, "buses[0].io[0].slots[3].module: names a GSDML module, but the IO device has no gsdml file");
  EXPECT_REPORTED(e, "buses[0].io[0].records[0].index: must be a user record index (0..0x7FFF) in 0..32767, got \"0x8000\"");
  EXPECT_REPORTED(e, "buses[0].io[0].records[0].data: must be 1..1024 octets in hex such as \"01 02 ff\", got \"1\"");
  EXPECT_REPORTED(e, "buses[0].io[0].records[1].data: must be 1..1024 octets in hex");
}

TEST(ProfinetPlans, TimingAndAddressingAreChecked) {
  const std::string e = errors_of(R"(gateway: { name: cell }
buses:
  - name: pn0
    type: profinet
    cycle_time: 3ms
    options: { reduction_ratio: 24, rt_class: 3 }
    devices:
      - { station: a, ip: 192.168.0.0 }
      - { station: b, ip: 10.0.0.7, netmask: 255.0.255.0 }
      - { station: c, ip: 10.0.0.8, gateway: 10.0.1.1 }
      - { station: d, ip: 300.1.1.1 }
  - name: pn1
    type: profinet
    cycle_time: 4ms
    options: { interface: eth2, reduction_ratio: 512 }
)");
  EXPECT_REPORTED(e, "buses[0].cycle_time: must be the PROFINET send clock, 31.25us x a power of two (250us, 500us, 1ms, 2ms or 4ms), got 3ms");
  EXPECT_REPORTED(e, "buses[0].options.interface: a profinet bus needs the Ethernet interface its network is plugged into");
  EXPECT_REPORTED(e, "buses[0].options.reduction_ratio: must be a power of two (1, 2, 4 ... 512), got 24");
  EXPECT_REPORTED(e, "buses[0].options.rt_class: only RT class 1 is supported (classes 2 and 3 are IRT, which needs "
                     "scheduling hardware), got 3");
  EXPECT_REPORTED(e, "buses[0].devices[0].ip: must be a unicast host address of its subnet (192.168.0.0/24), got 192.168.0.0");
  EXPECT_REPORTED(e, "buses[0].devices[1].netmask: must be a contiguous netmask such as 255.255.255.0, got 255.0.255.0");
  EXPECT_REPORTED(e, "buses[0].devices[2].gateway: must be another address of the station's subnet 10.0.0.0/24, got 10.0.1.1");
  EXPECT_REPORTED(e, "buses[0].devices[3].ip: must be an IPv4 address such as 192.168.0.10, got \"300.1.1.1\"");
  EXPECT_REPORTED(e, "buses[1].options.data_hold_factor: data_hold_factor x update time must be at most 1.92s, got 3 x 2048ms = 6144ms");
}

TEST(ProfinetPlans, AxesNeedADeviceWithAProfidriveSection) {
  EXPECT_REPORTED(errors_of(with_axis_x("{ name: x, bus: pn0, address: 1, device: generic-cia402, mechanics: "
                                        "{ encoder_counts_per_rev: 4096 }, profinet: { station: akd-x, telegram: 9 } }")),
                  "axes[0].device: device profile \"generic-cia402\" has no profidrive section, which an axis on a profinet "
                  "bus needs (profiles/devices/README.md \"PROFIdrive\")");
  EXPECT_REPORTED(errors_of(with_axis_x("{ name: x, bus: pn0, address: 1, device: kollmorgen-akd-profinet }")),
                  "axes[0].profinet: missing");
}

}  // namespace
}  // namespace drivegate::config

namespace drivegate::config {
namespace {

// `param get AXIS p930`: a PROFIdrive axis takes PNUs with an optional subindex; INDEX:SUB (a
// CANopen object) and anything else is refused in words, never taken as a PNU.
TEST(ProfinetPlans, ParametersAreNamedByPnu) {
  const Plan p = load_plan_from_string(kValid, "t.yaml", test::test_options());
  const BusPlan& b = p.buses[0];
  ASSERT_TRUE(b.type_info && b.type_info->find_parameter);
  const auto find = [&](std::string_view name) { return b.type_info->find_parameter(b.axes[0], name, {0x6041, 0}); };
  for (const auto& [name, pnu, sub] : {std::tuple{"p930", 930, 0}, std::tuple{"p930[1]", 930, 1},
                                        std::tuple{"P964.2", 964, 2}, std::tuple{"r947[7]", 947, 7},
                                        std::tuple{"p65535", 65535, 0}}) {
    const ParameterRef r = find(name);
    ASSERT_TRUE(r.id.has_value()) << name << ": " << r.error;
    EXPECT_EQ(r.id->index, pnu) << name;
    EXPECT_EQ(r.id->sub, sub) << name;
    EXPECT_EQ(r.type, core::ParamType::Unknown) << name;  // the drive's reply says its format
  }
  for (const char* bad : {"p", "p0", "p65536", "p930[", "p930[]", "p930.", "p93a", "x930", "p930[1", "p-1", "6041h:00"}) {
    const ParameterRef r = find(bad);
    EXPECT_FALSE(r.id.has_value()) << bad;
    EXPECT_NE(r.error.find("takes parameters by PNU: p930"), std::string::npos) << bad << ": " << r.error;
    EXPECT_FALSE(r.name_unknown) << bad;
  }
  EXPECT_NE(find("p930[256]").error.find("subindex 256 is beyond 255"), std::string::npos);
  const ParameterRef by_index = b.type_info->find_parameter(b.axes[0], "", {0x6041, 0});
  EXPECT_FALSE(by_index.id.has_value());
  EXPECT_NE(by_index.error.find("PROFIdrive axis 'x' takes parameters by PNU"), std::string::npos) << by_index.error;
}

}  // namespace
}  // namespace drivegate::config
