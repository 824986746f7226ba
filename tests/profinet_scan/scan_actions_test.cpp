// The PROFINET scan's write actions as written (`--set-name MAC=NAME`, `--set-ip MAC=SUITE`,
// `--permanent`, `--signal MAC|NAME`; adapters/profinet/scan.hpp profinet_scan_actions): what is
// taken, and one line for each argument that is refused, before anything is sent; `drivegated
// --scan` exits 2 for those (daemon/scan.hpp) and refuses actions for a bus type whose scanner does
// not write. No network.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "adapters/profinet/scan.hpp"
#include "config/loader.hpp"
#include "daemon/scan.hpp"

namespace drivegate::profinet {
namespace {

core::ScanRequest request(std::vector<core::ScanAction> actions, bool permanent = false) {
  core::ScanRequest q;
  q.bus_type = "profinet";
  q.where = "pnet0";
  q.actions = std::move(actions);
  q.permanent = permanent;
  return q;
}

// The one line an action list is refused with, or "(accepted)".
std::string refused(std::vector<core::ScanAction> actions, bool permanent = false) {
  try {
    (void)profinet_scan_actions(request(std::move(actions), permanent));
  } catch (const core::ScanUsageError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ProfinetScanActions, NamesIpSuitesAndSignalsAreTakenInOrder) {
  const auto a = profinet_scan_actions(request({{"--set-name", "00:1b:1b:00:0a:04=drive-d"},
                                                {"--set-ip", "00:1b:1b:00:0a:04=192.168.0.14/24"},
                                                {"--set-ip", "00:1b:1b:00:0a:05=10.1.2.3/255.255.0.0/10.1.0.1"},
                                                {"--signal", "drive-d"},
                                                {"--signal", "00:1B:1B:00:0A:05"}},
                                               true));
  ASSERT_EQ(a.size(), 5U);
  EXPECT_EQ(a[0].kind, DcpAction::Kind::SetName);
  EXPECT_EQ(a[0].mac, (MacAddress{0x00, 0x1B, 0x1B, 0x00, 0x0A, 0x04}));
  EXPECT_EQ(a[0].name, "drive-d");
  EXPECT_EQ(a[0].text, "--set-name 00:1b:1b:00:0a:04=drive-d");
  EXPECT_EQ(a[1].kind, DcpAction::Kind::SetIp);
  EXPECT_EQ(a[1].ip.address, (std::array<std::uint8_t, 4>{192, 168, 0, 14}));
  EXPECT_EQ(a[1].ip.netmask, (std::array<std::uint8_t, 4>{255, 255, 255, 0}));
  EXPECT_EQ(a[1].ip.gateway, (std::array<std::uint8_t, 4>{0, 0, 0, 0}));
  EXPECT_EQ(a[2].ip.netmask, (std::array<std::uint8_t, 4>{255, 255, 0, 0}));
  EXPECT_EQ(a[2].ip.gateway, (std::array<std::uint8_t, 4>{10, 1, 0, 1}));
  EXPECT_EQ(a[3].kind, DcpAction::Kind::Signal);
  EXPECT_TRUE(a[3].by_name);
  EXPECT_EQ(a[3].name, "drive-d");
  EXPECT_FALSE(a[4].by_name);
  EXPECT_EQ(a[4].mac, (MacAddress{0x00, 0x1B, 0x1B, 0x00, 0x0A, 0x05}));
  EXPECT_TRUE(profinet_scan_actions(request({})).empty());
}

TEST(ProfinetScanActions, EveryBadArgumentIsOneLine) {
  EXPECT_EQ(refused({{"--set-name", "drive-d"}}), "--set-name drive-d: expected MAC=NAME, e.g. 00:1b:1b:00:0a:04=drive-d");
  EXPECT_EQ(refused({{"--set-name", "00:1b:1b:00:0a=drive-d"}}),
            "--set-name 00:1b:1b:00:0a=drive-d: \"00:1b:1b:00:0a\" is no MAC address (six hex octets such as "
            "00:1b:1b:00:0a:04)");
  EXPECT_EQ(refused({{"--set-name", "01:0e:cf:00:00:00=drive-d"}}),
            "--set-name 01:0e:cf:00:00:00=drive-d: 01:0e:cf:00:00:00 is a multicast address, not a device's");
  EXPECT_EQ(refused({{"--set-name", "00:1b:1b:00:0a:04=Drive-D"}}),
            "--set-name 00:1b:1b:00:0a:04=Drive-D: \"Drive-D\" is no NameOfStation: the name has upper-case letters; "
            "PROFINET names are lower case");
  EXPECT_EQ(refused({{"--set-name", "00:1b:1b:00:0a:04="}}),
            "--set-name 00:1b:1b:00:0a:04=: \"\" is no NameOfStation: the name is empty");
  EXPECT_NE(refused({{"--set-name", "00:1b:1b:00:0a:04=port-001"}}).find("reserved for ports"), std::string::npos);
  EXPECT_EQ(refused({{"--set-name", "00:1b:1b:00:0a:04=a"}, {"--set-name", "00:1b:1b:00:0a:04=b"}}),
            "--set-name 00:1b:1b:00:0a:04=b: 00:1b:1b:00:0a:04 is given a name twice");
  EXPECT_EQ(refused({{"--set-name", "00:1b:1b:00:0a:04=a"}, {"--set-name", "00:1b:1b:00:0a:05=a"}}),
            "--set-name 00:1b:1b:00:0a:05=a: \"a\" is given to 00:1b:1b:00:0a:04 too");

  const std::string suite_usage =
      ": expected MAC=A.B.C.D/MASK[/GATEWAY] (MASK dotted or a prefix length), e.g. 00:1b:1b:00:0a:04=192.168.0.14/24";
  EXPECT_EQ(refused({{"--set-ip", "00:1b:1b:00:0a:04"}}),
            "--set-ip 00:1b:1b:00:0a:04: expected MAC=A.B.C.D/MASK[/GATEWAY], e.g. 00:1b:1b:00:0a:04=192.168.0.14/24");
  for (const char* bad : {"192.168.0.14", "192.168.0.14/", "192.168.0.14/33", "192.168.0.300/24", "192.168.0.14/24/x",
                          "192.168.0.14/24/192.168.0.1/1"})
    EXPECT_EQ(refused({{"--set-ip", std::string("00:1b:1b:00:0a:04=") + bad}}),
              std::string("--set-ip 00:1b:1b:00:0a:04=") + bad + suite_usage);
  EXPECT_EQ(refused({{"--set-ip", "00:1b:1b:00:0a:04=0.0.0.0/0"}}),
            "--set-ip 00:1b:1b:00:0a:04=0.0.0.0/0: 0.0.0.0 is no address to give a device");
  EXPECT_EQ(refused({{"--set-ip", "00:1b:1b:00:0a:04=192.168.0.255/24"}}),
            "--set-ip 00:1b:1b:00:0a:04=192.168.0.255/24: the IP suite is not usable: the address is the subnet's "
            "broadcast address");
  EXPECT_EQ(refused({{"--set-ip", "00:1b:1b:00:0a:04=192.168.0.14/255.0.255.0"}}),
            "--set-ip 00:1b:1b:00:0a:04=192.168.0.14/255.0.255.0: the IP suite is not usable: the netmask's ones are "
            "not contiguous");
  EXPECT_EQ(refused({{"--set-ip", "00:1b:1b:00:0a:04=192.168.0.14/24/10.0.0.1"}}),
            "--set-ip 00:1b:1b:00:0a:04=192.168.0.14/24/10.0.0.1: the IP suite is not usable: the gateway is outside "
            "the address's subnet");
  EXPECT_EQ(refused({{"--set-ip", "00:1b:1b:00:0a:04=192.168.0.14/24"}, {"--set-ip", "00:1b:1b:00:0a:04=192.168.0.15/24"}}),
            "--set-ip 00:1b:1b:00:0a:04=192.168.0.15/24: 00:1b:1b:00:0a:04 is given an IP suite twice");
  EXPECT_EQ(refused({{"--set-ip", "00:1b:1b:00:0a:04=192.168.0.14/24"}, {"--set-ip", "00:1b:1b:00:0a:05=192.168.0.14/24"}}),
            "--set-ip 00:1b:1b:00:0a:05=192.168.0.14/24: 192.168.0.14 is given to 00:1b:1b:00:0a:04 too");

  EXPECT_EQ(refused({{"--signal", "Drive D"}}),
            "--signal Drive D: \"Drive D\" is neither a MAC address (00:1b:1b:00:0a:04) nor a NameOfStation");
  EXPECT_EQ(refused({{"--signal", "ff:ff:ff:ff:ff:ff"}}),
            "--signal ff:ff:ff:ff:ff:ff: ff:ff:ff:ff:ff:ff is a multicast address, not a device's");
  EXPECT_EQ(refused({{"--signal", "drive-d"}}, true),
            "--permanent goes with --set-name or --set-ip (it makes the values they set survive a power loss)");
  EXPECT_EQ(refused({}, true),
            "--permanent goes with --set-name or --set-ip (it makes the values they set survive a power loss)");
  EXPECT_EQ(refused({{"--reset", "00:1b:1b:00:0a:04"}}),
            "--reset is not a profinet scan action (--set-name, --set-ip, --signal)");
}

TEST(ProfinetScanActions, ThePlanChecksThem) {
  const auto types = config::BusTypeRegistry::builtin();
  EXPECT_THROW((void)profinet_scan_plan(request({{"--set-name", "00:1b:1b:00:0a:04=Drive"}}), types),
               core::ScanUsageError);
  EXPECT_NO_THROW((void)profinet_scan_plan(request({{"--set-name", "00:1b:1b:00:0a:04=drive"}}), types));
}

// As drivegated runs it: a bad argument exits 2 with one line and nothing opened (the interface
// does not exist, which would be exit 1); a bus type whose scanner does not write refuses actions.
TEST(ProfinetScanActions, TheScanCommandExitsTwoForABadArgument) {
  const auto run = [](const std::string& target, std::vector<core::ScanAction> actions, bool permanent = false) {
    daemon::ScanCommand c;
    c.target = target;
    c.actions = std::move(actions);
    c.permanent = permanent;
    std::ostringstream out, err;
    const int rc = daemon::run_scan_command(c, out, err);
    return std::make_pair(rc, out.str() + err.str());
  };
  EXPECT_EQ(run("profinet:dgnosuch0", {{"--set-name", "00:1b:1b:00:0a:04=Drive"}}),
            std::make_pair(2, std::string("drivegated: --scan profinet:dgnosuch0: --set-name 00:1b:1b:00:0a:04=Drive: "
                                          "\"Drive\" is no NameOfStation: the name has upper-case letters; PROFINET "
                                          "names are lower case\n")));
  EXPECT_EQ(run("canopen:can0", {{"--signal", "00:1b:1b:00:0a:04"}}),
            std::make_pair(2, std::string("drivegated: --scan canopen:can0: --signal is not for canopen: only a scan of "
                                          "profinet writes to its devices\n")));
  EXPECT_EQ(run("ethercat:eth1", {}, true),
            std::make_pair(2, std::string("drivegated: --scan ethercat:eth1: --permanent is not for ethercat: only a "
                                          "scan of profinet writes to its devices\n")));
}

}  // namespace
}  // namespace drivegate::profinet
