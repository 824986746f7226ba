// DCP against a network of simulated devices: identify all, naming a device found by MAC, and the
// station finder assigning the configured IP suites.
#include <gtest/gtest.h>

#include "tests/profinet_sim/sim_bench.hpp"

namespace drivegate::profinet::test {
namespace {

struct Network {
  Network() {
    akd_a = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    akd_b = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    io = std::make_unique<GenericIoPersona>(GenericIoPersonaConfig{
        {{0, 0, 0x10, {{1, 0x10, 0, 0}}}, {0, 1, 0x20, {{1, 0x21, 2, 0}}}}, 0x0042, "IO-1", "1"});
    bench.net.add(device_config(1, "drive-a", suite(11)), *akd_a);
    bench.net.add(device_config(2, "drive-b", {}), *akd_b);
    bench.net.add(device_config(3, "", {}), *io);
  }
  std::unique_ptr<AkdPersona> akd_a, akd_b;
  std::unique_ptr<GenericIoPersona> io;
  SimBench bench;
};

TEST(PnSimDcp, IdentifyAllFindsEveryDevice) {
  Network n;
  std::array<DcpStation, 8> found{};
  const DcpRequestId id = n.bench.dcp.identify_all(found, 1);
  ASSERT_NE(id, kNoDcpRequest);
  ASSERT_TRUE(n.bench.run_until([&] { return n.bench.dcp.result(id).status == DcpRequestStatus::Done; }, 5s));
  const auto stations = n.bench.dcp.stations(id);
  ASSERT_EQ(stations.size(), 3U);
  std::vector<std::string> names;
  for (const DcpStation& s : stations) names.emplace_back(s.name());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"", "drive-a", "drive-b"}));
}

TEST(PnSimDcp, DeviceFoundByMacIsNamedThenTheFinderAssignsItsAddress) {
  Network n;
  const DcpRequestId named = n.bench.dcp.set_name(device_mac(3), "io-c", DcpQualifier::Permanent);
  ASSERT_TRUE(n.bench.run_until([&] { return n.bench.dcp.result(named).status == DcpRequestStatus::Done; }, 5s));
  EXPECT_EQ(n.bench.net.device(2).dcp().name_of_station(), "io-c");

  n.bench.finder = std::make_unique<StationFinder>(
      n.bench.dcp, std::vector<StationConfig>{{"drive-a", suite(11), kKollmorgen, kAkdDeviceId},
                                              {"drive-b", suite(12), {}, {}},
                                              {"io-c", suite(13), {}, {}},
                                              {"drive-x", suite(14), {}, {}}});
  ASSERT_TRUE(n.bench.run_until([&] { return n.bench.finder->done(); }, 30s));
  const auto& r = n.bench.finder->reports();
  EXPECT_EQ(r[0].outcome, StationOutcome::Ready) << r[0].text;
  EXPECT_EQ(r[1].outcome, StationOutcome::IpAssigned) << r[1].text;
  EXPECT_EQ(r[2].outcome, StationOutcome::IpAssigned) << r[2].text;
  EXPECT_EQ(r[3].outcome, StationOutcome::Missing) << r[3].text;
  EXPECT_EQ(n.bench.net.device(1).ip(), ip_of(12));
  EXPECT_EQ(n.bench.net.device(2).ip(), ip_of(13));
}

}  // namespace
}  // namespace drivegate::profinet::test
