// The start-up station finder against simulated devices: found and ready, IP assigned, missing,
// duplicate names, wrong device, refused IP, and configs it refuses without traffic. The report
// texts are what an operator reads, so they are checked whole.
#include <gtest/gtest.h>

#include <memory>

#include "tests/profinet_dcp/hub.hpp"

namespace drivegate::profinet::test {
namespace {

struct Line {
  Hub hub;
  DcpClient client{kControllerMac};
  std::vector<std::unique_ptr<DcpResponder>> devices;

  DcpResponder& add(const DcpResponderConfig& c) {
    devices.push_back(std::make_unique<DcpResponder>(c));
    hub.add(*devices.back());
    return *devices.back();
  }
  void run(StationFinder& f) {
    hub.add(f, kControllerMac);
    ASSERT_TRUE(hub.run_until([&] { return f.done(); }));
  }
};

StationConfig station(std::string name, std::uint8_t host, std::optional<std::uint16_t> vendor = std::nullopt,
                      std::optional<std::uint16_t> dev = std::nullopt) {
  return StationConfig{std::move(name), suite(host), vendor, dev};
}

TEST(PnStationFinder, EveryOutcomeWithItsText) {
  Line line;
  DcpResponder& ready = line.add(device(0x0A01, "drive-a", suite(10)));
  DcpResponder& moved = line.add(device(0x0A02, "drive-b", suite(99)));
  line.add(device(0x0A03, "drive-d"));
  line.add(device(0x0A04, "drive-d"));
  DcpResponder& other = line.add(device(0x0A05, "drive-e", suite(14)));
  DcpResponder& busy = line.add(device(0x0A06, "drive-f", suite(50)));
  busy.set_in_operation(true);

  StationFinder finder(line.client,
                       {station("drive-a", 10, 0x0118, 0x0501), station("drive-b", 11), station("drive-c", 12),
                        station("drive-d", 13), station("drive-e", 14, 0x0118, 0x0777), station("drive-f", 15)});
  line.run(finder);
  const auto& r = finder.reports();
  ASSERT_EQ(r.size(), 6U);
  EXPECT_FALSE(finder.all_ok());

  EXPECT_EQ(r[0].outcome, StationOutcome::Ready);
  EXPECT_EQ(r[0].mac, ready.mac());
  EXPECT_EQ(r[0].text, "station \"drive-a\": 00:1b:1b:00:0a:01 at 192.168.0.10/255.255.255.0 gateway 192.168.0.1, "
                       "vendor 0x0118 device 0x0501");
  EXPECT_EQ(ready.counters().sets, 0U);  // nothing set where nothing differs

  EXPECT_EQ(r[1].outcome, StationOutcome::IpAssigned);
  EXPECT_EQ(r[1].ip, suite(11));
  EXPECT_EQ(r[1].previous_ip, suite(99));
  EXPECT_EQ(moved.ip(), suite(11));
  EXPECT_EQ(r[1].text, "station \"drive-b\": 00:1b:1b:00:0a:02 at 192.168.0.11/255.255.255.0 gateway 192.168.0.1 "
                       "(set temporarily, was 192.168.0.99/255.255.255.0 gateway 192.168.0.1), vendor 0x0118 device 0x0501");

  EXPECT_EQ(r[2].outcome, StationOutcome::Missing);
  EXPECT_EQ(r[2].text, "station \"drive-c\": no device answers to this name (DCP Identify)");

  EXPECT_EQ(r[3].outcome, StationOutcome::Duplicate);
  ASSERT_EQ(r[3].macs.size(), 2U);
  EXPECT_NE(r[3].text.find("2 devices answer to this name ("), std::string::npos) << r[3].text;
  EXPECT_NE(r[3].text.find("00:1b:1b:00:0a:03"), std::string::npos) << r[3].text;
  EXPECT_NE(r[3].text.find("00:1b:1b:00:0a:04"), std::string::npos) << r[3].text;
  EXPECT_NE(r[3].text.find("none is used until only one has it"), std::string::npos) << r[3].text;
  EXPECT_EQ(line.devices[2]->counters().sets + line.devices[3]->counters().sets, 0U);

  EXPECT_EQ(r[4].outcome, StationOutcome::WrongDevice);
  EXPECT_EQ(r[4].mac, other.mac());
  EXPECT_EQ(r[4].text, "station \"drive-e\": 00:1b:1b:00:0a:05 reports vendor 0x0118 device 0x0501, the config "
                       "expects vendor 0x0118 device 0x0777");

  EXPECT_EQ(r[5].outcome, StationOutcome::IpSetFailed);
  EXPECT_EQ(r[5].text.rfind("station \"drive-f\": 00:1b:1b:00:0a:06: setting 192.168.0.15/255.255.255.0 gateway "
                            "192.168.0.1 failed: the device refused the value (BlockError): ", 0),
            0U)
      << r[5].text;
  EXPECT_EQ(busy.ip(), suite(50));
  EXPECT_TRUE(line.client.idle());
}

TEST(PnStationFinder, AllFoundIsAllOk) {
  Line line;
  line.add(device(1, "x1", suite(10)));
  line.add(device(2, "x2", IpSuite{}));
  StationFinderOptions opt;
  opt.ip_qualifier = DcpQualifier::Permanent;
  StationFinder finder(line.client, {station("x1", 10), station("x2", 11)}, opt);
  line.run(finder);
  EXPECT_TRUE(finder.all_ok());
  EXPECT_EQ(finder.reports()[1].text,
            "station \"x2\": 00:1b:1b:00:00:02 at 192.168.0.11/255.255.255.0 gateway 192.168.0.1 (set permanently, "
            "was no IP address), vendor 0x0118 device 0x0501");
  line.devices[1]->power_cycle();
  EXPECT_EQ(line.devices[1]->ip(), suite(11));
}

TEST(PnStationFinder, SetIpTimesOut) {
  Line line;
  line.add(device(1, "x1", suite(20)));
  // The device answers Identify but its Set responses are lost.
  line.hub.drop = [](std::span<const std::uint8_t> f) { return f[14] == 0xFE && f[15] == 0xFD && f[17] == 1; };
  StationFinder finder(line.client, {station("x1", 10)});
  line.run(finder);
  EXPECT_EQ(finder.reports()[0].outcome, StationOutcome::IpSetFailed);
  EXPECT_EQ(finder.reports()[0].text,
            "station \"x1\": 00:1b:1b:00:00:01: setting 192.168.0.10/255.255.255.0 gateway 192.168.0.1 failed: no "
            "response (timeout after every retry) after 3 frames");
}

TEST(PnStationFinder, InvalidConfigsAreRefusedWithoutTraffic) {
  Line line;
  IpSuite bad_mask = suite(12);
  bad_mask.netmask = {255, 255, 0, 255};
  StationFinder finder(line.client, {StationConfig{"Drive-1", suite(10), {}, {}}, StationConfig{"d2", IpSuite{}, {}, {}},
                                     StationConfig{"d3", bad_mask, {}, {}}, station("d4", 14), station("d4", 15),
                                     station("d5", 14)});
  line.run(finder);
  const auto& r = finder.reports();
  EXPECT_EQ(r[0].text, "station \"Drive-1\": the name is not a valid NameOfStation: " +
                           std::string(to_string(NameError::UpperCase)));
  EXPECT_EQ(r[1].text, "station \"d2\": no IP address configured");
  EXPECT_EQ(r[2].text, "station \"d3\": the configured IP suite 192.168.0.12/255.255.0.255 gateway 192.168.0.1 is "
                       "unusable: the netmask's ones are not contiguous");
  EXPECT_EQ(r[3].outcome, StationOutcome::Missing);
  EXPECT_EQ(r[4].text, "station \"d4\": the name is configured twice (station 4)");
  EXPECT_EQ(r[5].text, "station \"d5\": the address 192.168.0.14 is also configured for \"d4\"");
  for (std::size_t i : {0U, 1U, 2U, 4U, 5U}) EXPECT_EQ(r[i].outcome, StationOutcome::InvalidConfig) << i;
  EXPECT_EQ(line.hub.log.size(), 1U);  // only d4's Identify
}

TEST(PnStationFinder, IdentifyThatCannotBeSentIsReportedWithItsCause) {
  DcpClient client(kControllerMac);
  StationFinder finder(client, {station("x1", 10), station("x2", 11)});
  std::array<std::uint8_t, 20> tiny{};
  EXPECT_EQ(finder.poll(core::TimePoint{}, tiny), 0U);
  ASSERT_TRUE(finder.done());
  for (const StationReport& r : finder.reports()) {
    EXPECT_EQ(r.outcome, StationOutcome::Missing);
    EXPECT_NE(r.text.find("DCP Identify failed: the request's frame does not fit the buffer given to poll()"),
              std::string::npos)
        << r.text;
  }
}

}  // namespace
}  // namespace drivegate::profinet::test
