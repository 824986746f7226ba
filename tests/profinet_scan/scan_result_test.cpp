// The PROFINET scan's result from DCP Identify answers (adapters/profinet/scan.hpp): the table's
// rows, the profile matched by the profidrive identity, the flags for stations without a name or
// with a name twice, and the skeleton, which the configuration loader accepts as --check-config
// does. The scan's request options. No network.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "adapters/profinet/scan.hpp"
#include "config/loader.hpp"
#include "config/profinet/plan.hpp"
#include "daemon/scan.hpp"

namespace drivegate::profinet {
namespace {

using namespace std::chrono_literals;

constexpr std::uint32_t kIface = 0xC0A80001;  // 192.168.0.1/24

DcpStation station(std::uint8_t n, const std::string& name, std::uint8_t host, std::uint16_t vendor, std::uint16_t device,
                   const std::string& type = "AKD") {
  DcpStation s;
  s.mac = {0x00, 0x1B, 0x1B, 0x00, 0x0A, n};
  s.has_name = !name.empty();
  s.name_length = static_cast<std::uint8_t>(name.size());
  std::memcpy(s.name_chars.data(), name.data(), name.size());
  s.has_type_of_station = true;
  s.type_length = static_cast<std::uint8_t>(type.size());
  std::memcpy(s.type_chars.data(), type.data(), type.size());
  s.has_device_id = true;
  s.vendor_id = vendor;
  s.device_id = device;
  s.has_device_role = true;
  s.device_role = device_role::kIoDevice;
  s.has_ip = true;
  if (host != 0) {
    s.ip_block_info = ip_block_info::kSet;
    s.ip.address = {192, 168, 0, host};
    s.ip.netmask = {255, 255, 255, 0};
    s.ip.gateway = {192, 168, 0, 1};
  }
  return s;
}

DcpStation akd(std::uint8_t n, const std::string& name, std::uint8_t host) { return station(n, name, host, 0x0118, 0x0501); }
DcpStation io(std::uint8_t n, const std::string& name, std::uint8_t host) {
  return station(n, name, host, 0x0FEE, 0x0042, "IO-1");
}

std::vector<config::DeviceProfile> profiles() {
  std::vector<std::string> notes;
  auto p = profinet_scan_profiles(config::default_device_dirs(), config::BusTypeRegistry::builtin(), notes);
  EXPECT_TRUE(notes.empty()) << notes.front();
  return p;
}

core::ScanResult scan(const std::vector<DcpStation>& stations, std::uint32_t address = kIface) {
  return profinet_scan_result(stations, ScanInterface{"pnet0", address, address != 0 ? 0xFFFFFF00U : 0}, profiles());
}

config::Plan load(const std::string& text) {
  return config::load_plan_from_string(text, "skeleton.yaml", config::LoadOptions{});
}

TEST(ProfinetScanResult, TwoDrivesAndAnIoDeviceInTheTableWithTheirProfile) {
  const auto r = scan({io(3, "io-b", 13), akd(2, "drive-b", 12), akd(1, "drive-a", 11)});
  ASSERT_EQ(r.devices.size(), 3U);
  // By station name.
  EXPECT_EQ(r.devices[0].address.text, "drive-a 192.168.0.11 00:1b:1b:00:0a:01");
  EXPECT_EQ(r.devices[1].address.text, "drive-b 192.168.0.12 00:1b:1b:00:0a:02");
  EXPECT_EQ(r.devices[2].address.text, "io-b 192.168.0.13 00:1b:1b:00:0a:03");
  EXPECT_EQ(r.devices[0].profile, "kollmorgen-akd-profinet");
  EXPECT_EQ(r.devices[0].profile_reason, "vendor 0x0118 device 0x0501 is its profidrive identity");
  EXPECT_TRUE(r.devices[0].drive);
  EXPECT_EQ(r.devices[0].axis_keys, std::vector<std::string>{"profinet: { station: drive-a, telegram: 352 }"});
  EXPECT_EQ(r.devices[2].profile, "");
  EXPECT_FALSE(r.devices[2].drive);
  EXPECT_EQ(r.devices[2].profile_reason,
            "vendor 0x0FEE device 0x0042 matches no device profile (profidrive: vendor_id, device_id)");
  EXPECT_TRUE(r.warnings.empty());

  const std::string t = daemon::format_scan_table(r);
  EXPECT_NE(t.find("profinet on pnet0: 3 devices"), std::string::npos) << t;
  // Address (station, IP, MAC), role, vendor ID, device ID, TypeOfStation, profile.
  for (const char* row : {"drive-a 192.168.0.11 00:1b:1b:00:0a:01  -            IO device  0x00000118  0x00000501",
                          "io-b 192.168.0.13 00:1b:1b:00:0a:03     -            IO device  0x00000FEE  0x00000042"})
    EXPECT_NE(t.find(row), std::string::npos) << row << "\n" << t;
  EXPECT_NE(t.find("\"AKD\"   -         -         kollmorgen-akd-profinet\n"), std::string::npos) << t;
  EXPECT_NE(t.find("\"IO-1\"  -         -         (none)\n"), std::string::npos) << t;
  EXPECT_NE(t.find("    MAC 00:1b:1b:00:0a:01, role IO device\n    IP 192.168.0.11/255.255.255.0 gateway 192.168.0.1 "
                   "(set)\n"),
            std::string::npos)
      << t;
}

TEST(ProfinetScanResult, TheSkeletonPassesTheConfigurationChecks) {
  const auto r = scan({akd(1, "drive-a", 11), akd(2, "drive-b", 12), io(3, "io-b", 13)});
  const std::string text = daemon::scan_skeleton(r, config::LoadOptions{});
  const config::Plan plan = load(text);
  ASSERT_EQ(plan.buses.size(), 1U);
  const config::BusPlan& bus = plan.buses[0];
  EXPECT_EQ(bus.type, "profinet");
  const auto& o = bus.section<config::ProfinetBusOptions>();
  EXPECT_EQ(o.interface, "pnet0");
  // The AKD needs 16 ms [akd-profinet-profidrive.md §2]: 1 ms x 16.
  EXPECT_EQ(bus.cycle_time, 1ms);
  EXPECT_EQ(o.reduction_ratio, 16);
  ASSERT_EQ(o.stations.size(), 3U);
  EXPECT_EQ(o.stations[0].name, "drive-a");
  EXPECT_EQ(o.stations[0].ip, 0xC0A8000BU);
  EXPECT_EQ(o.stations[0].netmask, 0xFFFFFF00U);
  EXPECT_EQ(o.stations[0].gateway, 0xC0A80001U);
  EXPECT_EQ(o.stations[0].vendor_id, 0x0118);
  EXPECT_EQ(o.stations[0].device_id, 0x0501);
  EXPECT_EQ(o.stations[2].name, "io-b");
  EXPECT_TRUE(o.io.empty());
  ASSERT_EQ(bus.axes.size(), 2U);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(bus.axes[i].device.name, "kollmorgen-akd-profinet");
    EXPECT_EQ(bus.axes[i].section<config::ProfinetAxisSpec>().telegram, 352);
    // 352 carries MDI, speed, homing and program mode [§14].
    EXPECT_TRUE(bus.axes[i].spec.modes.contains(core::Mode::ProfilePosition));
    EXPECT_TRUE(bus.axes[i].spec.modes.contains(core::Mode::TraversingBlock));
  }
  EXPECT_EQ(bus.axes[1].section<config::ProfinetAxisSpec>().station, "drive-b");
  EXPECT_NE(text.find("      reduction_ratio: 16    # CHECK: update time 16ms = cycle_time x this; "
                      "kollmorgen-akd-profinet needs at least 16ms\n"),
            std::string::npos)
      << text;
  // The IO device: a commented-out io: entry saying what to give.
  EXPECT_NE(text.find("    io: []\n      # - { name: io-3, station: io-b, gsdml: FILE }    # CHECK: give its slots"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("not an axis here: not a known drive"), std::string::npos) << text;
}

TEST(ProfinetScanResult, StationsWithoutANameOrWithOneNameTwiceAreFlaggedAndLeftOut) {
  auto bad = akd(5, "Drive-X", 15);  // upper case: breaks the NameOfStation rules
  const auto r = scan({akd(1, "", 11), akd(2, "twin", 12), io(3, "twin", 13), bad, akd(4, "drive-d", 14)});
  ASSERT_EQ(r.devices.size(), 5U);
  // Named ones first by name ("Drive-X" < "drive-d" < "twin"), the nameless last.
  EXPECT_EQ(r.devices[0].address.text, "Drive-X 192.168.0.15 00:1b:1b:00:0a:05");
  EXPECT_EQ(r.devices[4].address.text, "(no name) 192.168.0.11 00:1b:1b:00:0a:01");
  EXPECT_FALSE(r.devices[4].drive);
  EXPECT_EQ(r.devices[4].profile, "kollmorgen-akd-profinet");  // known, but it cannot be addressed
  EXPECT_FALSE(r.devices[0].drive);
  EXPECT_NE(r.devices[0].next_step.find("breaks the NameOfStation rules"), std::string::npos) << r.devices[0].next_step;
  for (const std::size_t k : {2U, 3U}) {
    EXPECT_EQ(r.devices[k].conflict,
              "station \"twin\" is answered by 2 devices (00:1b:1b:00:0a:02, 00:1b:1b:00:0a:03)");
    EXPECT_EQ(r.devices[k].profile, "");
  }
  ASSERT_EQ(r.warnings.size(), 3U);
  EXPECT_NE(r.warnings[0].find("00:1b:1b:00:0a:05: its NameOfStation \"Drive-X\" breaks"), std::string::npos);
  EXPECT_EQ(r.warnings[1], "station \"twin\" is answered by 2 devices (00:1b:1b:00:0a:02, 00:1b:1b:00:0a:03); each "
                           "needs a name of its own");
  EXPECT_EQ(r.warnings[2], "00:1b:1b:00:0a:01: it answers without a NameOfStation; it needs a name before use");

  const std::string t = daemon::format_scan_table(r);
  EXPECT_NE(t.find("(conflict)\n"), std::string::npos) << t;
  EXPECT_NE(t.find("(no name) 192.168.0.11"), std::string::npos) << t;
  EXPECT_NE(t.find("warning: 00:1b:1b:00:0a:01: it answers without a NameOfStation"), std::string::npos) << t;

  const std::string text = daemon::scan_skeleton(r, config::LoadOptions{});
  const config::Plan plan = load(text);
  const auto& o = plan.buses[0].section<config::ProfinetBusOptions>();
  ASSERT_EQ(o.stations.size(), 1U);  // drive-d only
  EXPECT_EQ(o.stations[0].name, "drive-d");
  ASSERT_EQ(plan.buses[0].axes.size(), 1U);
  EXPECT_NE(text.find("not an axis here: station \"twin\" is answered by 2 devices (00:1b:1b:00:0a:02, "
                      "00:1b:1b:00:0a:03);\n  #   give each of them a NameOfStation of its own and scan again\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("not an axis here: it answers without a NameOfStation: no configuration can address it"),
            std::string::npos)
      << text;
}

TEST(ProfinetScanResult, AStationWithoutAUsableAddressGetsAFreeOneMarkedCheck) {
  auto twin_ip = akd(3, "drive-c", 11);  // drive-a's address
  auto outside = io(4, "io-d", 0);
  outside.ip.address = {10, 0, 0, 7};
  outside.ip.netmask = {255, 0, 0, 0};
  const auto r = scan({akd(1, "drive-a", 11), akd(2, "drive-b", 0), twin_ip, outside});
  const std::string text = daemon::scan_skeleton(r, config::LoadOptions{});
  const config::Plan plan = load(text);
  const auto& o = plan.buses[0].section<config::ProfinetBusOptions>();
  ASSERT_EQ(o.stations.size(), 4U);
  // The lowest hosts not taken (.1 is the interface, .11 drive-a).
  EXPECT_EQ(o.stations[0].ip, 0xC0A8000BU);
  EXPECT_EQ(o.stations[1].ip, 0xC0A80002U);
  EXPECT_EQ(o.stations[2].ip, 0xC0A80003U);
  EXPECT_EQ(o.stations[3].ip, 0xC0A80004U);
  EXPECT_NE(text.find("- { station: drive-b, ip: 192.168.0.2, netmask: 255.255.255.0, vendor_id: 0x0118, device_id: "
                      "0x0501 }    # CHECK: the station has no IP address; a suggested free address of pnet0's subnet"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("# CHECK: its address 192.168.0.11 is another station's too"), std::string::npos) << text;
  EXPECT_NE(text.find("# CHECK: its address 10.0.0.7 is outside pnet0's subnet 192.168.0.0/24"), std::string::npos)
      << text;
  // Without an address on the interface: 192.168.0.0/24, and it says why.
  const std::string bare = daemon::scan_skeleton(scan({akd(2, "drive-b", 0)}, 0), config::LoadOptions{});
  EXPECT_NE(bare.find("ip: 192.168.0.2, netmask: 255.255.255.0"), std::string::npos) << bare;
  EXPECT_NE(bare.find("192.168.0.0/24 (pnet0 has no IPv4 address)"), std::string::npos) << bare;
  (void)load(bare);
}

TEST(ProfinetScanResult, NobodyAnsweredIsABusWithoutDevices) {
  const auto r = scan({});
  EXPECT_NE(daemon::format_scan_table(r).find("profinet on pnet0: no devices answered"), std::string::npos);
  const std::string text = daemon::scan_skeleton(r, config::LoadOptions{});
  EXPECT_NE(text.find("    devices: []\n"), std::string::npos) << text;
  EXPECT_NE(text.find("axes: []\n"), std::string::npos) << text;
  EXPECT_TRUE(load(text).buses[0].axes.empty());
}

TEST(ProfinetScanResult, TheTelegramWithTheMostModes) {
  const auto p = profiles();
  const auto akd_profile = std::find_if(p.begin(), p.end(), [](const auto& x) { return x.name == "kollmorgen-akd-profinet"; });
  ASSERT_NE(akd_profile, p.end());
  EXPECT_EQ(skeleton_telegram(*akd_profile), 352);
  config::DeviceProfile speed_only = *akd_profile;
  speed_only.sections.edit<config::ProfidriveDeviceSpec>().telegrams = {0, 1, 350, 400};
  EXPECT_EQ(skeleton_telegram(speed_only), 1);
  speed_only.sections.edit<config::ProfidriveDeviceSpec>().telegrams = {0};
  EXPECT_EQ(skeleton_telegram(speed_only), 0);
}

TEST(ProfinetScanPlan, TheInterfaceAndTheResponseDelay) {
  const auto types = config::BusTypeRegistry::builtin();
  core::ScanRequest q;
  q.bus_type = "profinet";
  q.where = "pnet0";
  EXPECT_EQ(profinet_scan_plan(q, types).section<config::ProfinetBusOptions>().interface, "pnet0");
  EXPECT_EQ(profinet_scan_response_delay(q), kScanResponseDelayFactor);
  q.where = "pnet0?response_delay=1";
  EXPECT_EQ(profinet_scan_response_delay(q), 1);
  (void)profinet_scan_plan(q, types);
  const auto refused = [&](const std::string& where) {
    q.where = where;
    try {
      (void)profinet_scan_plan(q, types);
    } catch (const core::ScanError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(refused(""), "name the Ethernet interface the PROFINET network is on: profinet:eth1");
  EXPECT_EQ(refused("pnet0?response_delay=0"),
            "response_delay=\"0\": the DCP ResponseDelayFactor, 1..6400 (the answers spread over N x 10 ms)");
  EXPECT_EQ(refused("pnet0?response_delay=6401").find("response_delay=\"6401\""), 0U);
  EXPECT_EQ(refused("pnet0?objects=1"), "\"objects\" is not a scan option of profinet; it takes response_delay");
  EXPECT_EQ(refused("pnet0?delay"), "option \"delay\" is not KEY=VALUE");
  EXPECT_EQ(refused("a b"), "\"a b\": an interface name is letters, digits, '.', '_', '-' and '@'");
  EXPECT_NE(refused("averyveryverylonginterfacename").find("interface"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::profinet
