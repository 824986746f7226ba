// The drivegate-sim binary serving a config's profinet bus on end B of a veth pair (its own network
// namespace, which carries the stations' configured addresses), driven through its console on a
// pipe; on end A the controller's DcpClient and StationFinder find the stations by name and give
// them their addresses, a CmClient then connects to one over UDP at its new address (the tool
// opened the device's ports there), and a power loss from the console silences a station.
// Skipped without root.
// Also: what the binary says about an interface it cannot open (no root needed).
#include <gtest/gtest.h>

#include <poll.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "tests/profinet_sim/veth_controller.hpp"
#include "tests/profinet_simtool/support.hpp"
#include "tests/support/netns.hpp"
#include "tests/support/tool_process.hpp"

namespace drivegate::profinet::test {
namespace {

using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::ToolProcess;
using drivegate::test::VethPair;

std::filesystem::path write_config(const std::string& name, const std::string& yaml) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("drivegate-pn-sim-test-" + std::to_string(::getpid()) + "-" + name + ".yaml");
  std::ofstream(path) << yaml;
  return path;
}

// The part of a status answer about `station`, up to its `;`.
std::string item(const std::string& status, const std::string& station) {
  const auto at = status.find(" pn0:" + station + " ");
  if (at == std::string::npos) return {};
  return status.substr(at + 1, status.find(';', at) - at - 1);
}

class PnSimProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_gw_ = std::make_unique<NetNamespace>();
    ns_sim_ = std::make_unique<NetNamespace>();
    veth_ = std::make_unique<VethPair>(ns_gw_.get(), ns_sim_.get());
    veth_->set(VethPair::End::A, {"address", "02:00:00:00:00:01"});
    ASSERT_TRUE(ns_gw_->ip({"addr", "add", "192.168.0.1/24", "dev", veth_->a()}).ok());
    // The addresses the stations will be given, so that their UDP ports can open there.
    for (const char* a : {"192.168.0.10/24", "192.168.0.11/24", "192.168.0.20/24"}) {
      ASSERT_TRUE(ns_sim_->ip({"addr", "add", a, "dev", veth_->b()}).ok());
    }
    // The gateway's config names its own end (A); the simulator is told its end (B).
    config_ = write_config("veth", pn_config(veth_->a()));
    {
      const NetnsScope in(*ns_sim_);
      sim_ = std::make_unique<ToolProcess>(DRIVEGATE_SIM_EXE, std::vector<std::string>{config_.string(), "--interface", veth_->b()});
    }
    controller_ = std::make_unique<VethController>(veth_->a());
    const NetnsScope in(*ns_gw_);
    controller_->open();
  }
  void TearDown() override {
    sim_.reset();
    if (!config_.empty()) std::filesystem::remove(config_);
  }

  // Runs the controller on end A until `done` or 10 s.
  bool run_until(const std::function<bool()>& done) {
    std::vector<pollfd> fds;
    for (const int fd : controller_->wait_fds()) fds.push_back({fd, POLLIN, 0});
    const core::SteadyClock clock;
    for (const core::TimePoint end = clock.now() + 10s; clock.now() < end;) {
      controller_->poll(clock.now());
      if (done()) return true;
      (void)::poll(fds.data(), fds.size(), 1);
    }
    return done();
  }

  std::unique_ptr<NetNamespace> ns_gw_;
  std::unique_ptr<NetNamespace> ns_sim_;
  std::unique_ptr<VethPair> veth_;
  std::filesystem::path config_;
  std::unique_ptr<ToolProcess> sim_;
  std::unique_ptr<VethController> controller_;
};

TEST_F(PnSimProcess, TheControllerFindsTheStationsByNameAndGivesThemTheirAddresses) {
  // One line per device with its MAC, then the ready line.
  EXPECT_EQ(sim_->line(), "drivegate-sim: pn0 station akd-x: kollmorgen-akd-profinet (axis x), MAC 02:50:4e:00:00:01, no IP address")
      << sim_->error_text();
  EXPECT_EQ(sim_->line(), "drivegate-sim: pn0 station akd-y: kollmorgen-akd-profinet (axis y), MAC 02:50:4e:00:00:02, no IP address");
  EXPECT_EQ(sim_->line(), "drivegate-sim: pn0 station io-block: generic-io (io panel), MAC 02:50:4e:00:00:03, no IP address");
  ASSERT_EQ(sim_->line(), "drivegate-sim: 3 devices on profinet " + veth_->b() + " (bus pn0)");
  EXPECT_EQ(item(sim_->command("status"), "akd-x"),
            "pn0:akd-x kollmorgen-akd-profinet name=akd-x mac=02:50:4e:00:00:01 ip=0.0.0.0 ar=NoAr cycles=0 watchdog=0 "
            "alarm-cr=0 rx-lost=0 tx-lost=0 alarms=-");
  // io goes to the PROFINET console, also naming no station when no EtherCAT line is simulated.
  EXPECT_EQ(sim_->command("io io-block 1"), "io pn0:io-block 1:1 out=- out-state=lost in=0000");
  EXPECT_EQ(sim_->command("io nosuch 1"), "error: no simulated PROFINET station nosuch");

  const config::Plan plan = plan_of(pn_config(veth_->a()));
  DcpClient& dcp = controller_->dcp;
  controller_->finder = std::make_unique<StationFinder>(dcp, stations_of(plan.buses[0].section<config::ProfinetBusOptions>()));
  StationFinder& finder = *controller_->finder;
  ASSERT_TRUE(run_until([&] { return finder.done(); }));
  ASSERT_EQ(finder.reports().size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    const StationReport& r = finder.reports()[i];
    EXPECT_EQ(r.outcome, StationOutcome::IpAssigned) << r.text;
    EXPECT_EQ(r.mac, (MacAddress{0x02, 0x50, 0x4E, 0x00, 0x00, static_cast<std::uint8_t>(i + 1)})) << r.text;
  }
  const std::string status = sim_->command("status");
  EXPECT_NE(item(status, "akd-x").find(" ip=192.168.0.10 ar=NoAr "), std::string::npos) << status;
  EXPECT_NE(item(status, "akd-y").find(" ip=192.168.0.11 "), std::string::npos) << status;
  EXPECT_NE(item(status, "io-block").find(" ip=192.168.0.20 "), std::string::npos) << status;
  controller_->finder.reset();

  // A Connect to akd-x at its new address (the [sim] IDs are the test bench's), to data exchange.
  ArPlan ar(akd_plan(1, 4, 4), 0xC0A8000A, MacAddress{0x02, 0x50, 0x4E, 0x00, 0x00, 0x01}, 0);
  ASSERT_TRUE(controller_->connect(ar, core::SteadyClock{}.now()));
  CmClient& cm = controller_->cm();
  ASSERT_TRUE(run_until([&] { return cm.state() == CmClientState::DataExchange || cm.state() == CmClientState::Failed; }));
  ASSERT_EQ(cm.state(), CmClientState::DataExchange) << cm.reason();
  ASSERT_TRUE(run_until([&] { return ar.consumer->counters().frames >= 3; })) << ar.consumer->reason();
  EXPECT_NE(item(sim_->command("status"), "akd-x").find(" ar=DataExchange "), std::string::npos);

  // A power loss: akd-y no longer answers; back, it answers without its (temporary) address.
  EXPECT_EQ(sim_->command("power-off akd-y"), "ok power-off pn0:akd-y");
  std::array<DcpStation, 8> found{};
  DcpRequestId id = dcp.identify_all(found, 1);
  ASSERT_TRUE(run_until([&] { return dcp.result(id).status == DcpRequestStatus::Done; }));
  EXPECT_EQ(dcp.stations(id).size(), 2U);
  EXPECT_EQ(sim_->command("power-on akd-y"), "ok power-on pn0:akd-y");
  id = dcp.identify_name("akd-y", found, 1);
  ASSERT_TRUE(run_until([&] { return dcp.result(id).status == DcpRequestStatus::Done; }));
  ASSERT_EQ(dcp.stations(id).size(), 1U);
  EXPECT_EQ(dcp.stations(id)[0].ip.address, (std::array<std::uint8_t, 4>{}));
  EXPECT_EQ(sim_->stop(), 0);
  EXPECT_EQ(sim_->error_text(), "");
}

TEST(PnSimTool, AnInterfaceItCannotOpenIsNamed) {
  const auto config = write_config("nosuch", pn_config("dgtnosuch0"));
  ToolProcess sim(DRIVEGATE_SIM_EXE, {config.string()});
  EXPECT_EQ(sim.stop(false), 1);
  const std::string err = sim.error_text();
  std::filesystem::remove(config);
  EXPECT_EQ(err.rfind("drivegate-sim: profinet: ", 0), 0U) << err;
  EXPECT_NE(err.find("dgtnosuch0"), std::string::npos) << err;
}

}  // namespace
}  // namespace drivegate::profinet::test
