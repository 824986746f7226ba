// The simulated network of a config's profinet bus (network_builder): one device per station with
// the persona of what uses it, its MAC, its stored name and no address; the controller's station
// finder naming and addressing them in memory; what the builder refuses, with its message.
#include <gtest/gtest.h>

#include "adapters/profinet/sim/network_builder.hpp"
#include "tests/profinet_sim/sim_bench.hpp"
#include "tests/profinet_simtool/support.hpp"

namespace drivegate::profinet::test {
namespace {

std::string build_error(const config::BusPlan& bus) {
  try {
    (void)build_pn_network(bus, 0);
  } catch (const PnBuildError& e) {
    return e.what();
  }
  return "(built)";
}

TEST(PnSimBuilder, TwoAkdAxesAndAnIoDeviceMakeThreeDevices) {
  const config::Plan plan = plan_of(pn_config("eth1"));
  const auto net = build_pn_network(plan.buses.at(0), 0);
  EXPECT_EQ(net->bus(), "pn0");
  ASSERT_EQ(net->size(), 3U);
  ASSERT_EQ(net->network().size(), 3U);

  const PnSimStation& x = net->station(0);
  EXPECT_EQ(x.name, "akd-x");
  EXPECT_EQ(x.persona, "kollmorgen-akd-profinet");
  EXPECT_EQ(x.used_by, "axis x");
  ASSERT_NE(x.akd, nullptr);
  EXPECT_EQ(x.io, nullptr);
  EXPECT_EQ(x.akd->telegram(), 9);  // the axis' telegram is plugged
  EXPECT_EQ(x.device->mac(), (MacAddress{0x02, 0x50, 0x4E, 0x00, 0x00, 0x01}));
  EXPECT_EQ(x.device->name_of_station(), "akd-x");
  EXPECT_EQ(x.device->ip(), 0U);  // the controller assigns it

  const PnSimStation& y = net->station(1);
  EXPECT_EQ(y.used_by, "axis y");
  ASSERT_NE(y.akd, nullptr);
  EXPECT_EQ(y.akd->telegram(), 1);
  EXPECT_EQ(y.device->mac(), (MacAddress{0x02, 0x50, 0x4E, 0x00, 0x00, 0x02}));

  const PnSimStation& io = net->station(2);
  EXPECT_EQ(io.name, "io-block");
  EXPECT_EQ(io.persona, "generic-io");
  EXPECT_EQ(io.used_by, "io panel");
  ASSERT_NE(io.io, nullptr);
  EXPECT_EQ(io.akd, nullptr);
  EXPECT_EQ(io.device->mac(), (MacAddress{0x02, 0x50, 0x4E, 0x00, 0x00, 0x03}));
  // The DAP (the config's ident, submodule [sim] 1) and the two submodules with their idents.
  const auto slots = io.io->slots();
  ASSERT_EQ(slots.size(), 3U);
  EXPECT_EQ(slots[0].slot, 0);
  EXPECT_EQ(slots[0].module_ident, 0x100U);
  ASSERT_EQ(slots[0].submodules.size(), 1U);
  EXPECT_EQ(slots[0].submodules[0].ident, kSimDapSubmodule);
  EXPECT_EQ(slots[1].slot, 1);
  EXPECT_EQ(slots[1].module_ident, 0x210U);
  EXPECT_EQ(slots[1].submodules[0].ident, 0x11U);
  EXPECT_EQ(slots[2].slot, 2);
  EXPECT_EQ(slots[2].module_ident, 0x220U);
  EXPECT_EQ(slots[2].submodules[0].ident, 0x12U);
  const PnPersona::IoLengths in = io.io->lengths(0, 1, 1);
  const PnPersona::IoLengths out = io.io->lengths(0, 2, 1);
  EXPECT_TRUE(in.found && in.input == 2 && in.output == 0);
  EXPECT_TRUE(out.found && out.input == 0 && out.output == 1);

  // The name is stored (an engineering tool set it): a power cycle keeps it.
  PnDevice& d = *net->station(0).device;
  d.power_loss();
  d.power_return({});
  EXPECT_EQ(d.name_of_station(), "akd-x");
  EXPECT_EQ(d.ip(), 0U);
  EXPECT_EQ(net->find("io-block"), &net->station(2));
  EXPECT_EQ(net->find("nosuch"), nullptr);
}

TEST(PnSimBuilder, AStationNobodyUsesIsADeviceWithOnlyItsDap) {
  const config::Plan plan = plan_of(pn_config("eth1", "      - { station: spare, ip: 192.168.0.30 }\n"));
  const auto net = build_pn_network(plan.buses.at(0), 2);
  ASSERT_EQ(net->size(), 4U);
  const PnSimStation& spare = net->station(3);
  EXPECT_EQ(spare.persona, "generic-io");
  EXPECT_EQ(spare.used_by, "");
  ASSERT_EQ(spare.io->slots().size(), 1U);
  EXPECT_EQ(spare.io->slots()[0].module_ident, kSimDapModule);
  // The bus index is in the MACs: another bus, other MACs.
  EXPECT_EQ(spare.device->mac(), (MacAddress{0x02, 0x50, 0x4E, 0x02, 0x00, 0x04}));
  EXPECT_EQ(sim_station_mac(1, 0x1233), (MacAddress{0x02, 0x50, 0x4E, 0x01, 0x12, 0x34}));
  EXPECT_THROW((void)sim_station_mac(256, 0), PnBuildError);
}

TEST(PnSimBuilder, TheControllerFindsTheStationsByNameAndAssignsTheirAddresses) {
  const config::Plan plan = plan_of(pn_config("eth1"));
  const auto net = build_pn_network(plan.buses.at(0), 0);
  SimBench bench(net->network());
  bench.finder = std::make_unique<StationFinder>(bench.dcp, stations_of(plan.buses[0].section<config::ProfinetBusOptions>()));
  ASSERT_TRUE(bench.run_until([&] { return bench.finder->done(); }, 30s));
  const auto& r = bench.finder->reports();
  ASSERT_EQ(r.size(), 3U);
  for (std::size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(r[i].outcome, StationOutcome::IpAssigned) << r[i].text;
    EXPECT_EQ(r[i].mac, net->station(i).device->mac()) << r[i].text;
  }
  // akd-y's IDs are the configured ones (the finder checks them), the others the [sim] ones.
  EXPECT_EQ(r[0].vendor_id, kSimAkdVendorId);
  EXPECT_EQ(r[0].device_id, kSimAkdDeviceId);
  EXPECT_EQ(r[1].vendor_id, 0x0FEE);
  EXPECT_EQ(r[1].device_id, 0x0042);
  EXPECT_EQ(r[2].vendor_id, kSimIoVendorId);
  EXPECT_EQ(net->station(0).device->ip(), 0xC0A8000AU);
  EXPECT_EQ(net->station(2).device->ip(), 0xC0A80014U);
}

TEST(PnSimBuilder, AnAxisWithoutASimulatedDeviceIsRefusedWithOneLine) {
  config::Plan plan = plan_of(pn_config("eth1"));
  plan.buses[0].axes[1].device.name = "acme-drive";
  EXPECT_EQ(build_error(plan.buses[0]),
            "bus 'pn0', station 'akd-y' (axis 'y'): device profile 'acme-drive' has no simulated PROFINET device "
            "(drivegate-sim simulates kollmorgen-akd-profinet)");
  plan = plan_of(pn_config("eth1"));
  plan.buses[0].axes[0].sections.edit<config::ProfinetAxisSpec>().telegram = 0;
  EXPECT_EQ(build_error(plan.buses[0]),
            "bus 'pn0', station 'akd-x' (axis 'x'): the simulated AKD has no module for telegram 0");
}

}  // namespace
}  // namespace drivegate::profinet::test
