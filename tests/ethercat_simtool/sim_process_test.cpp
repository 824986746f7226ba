// The drivegate-sim binary with a config's ethercat bus, served on end B of a veth pair (its own
// network namespace), driven through its console on a pipe; the master's engines on end A count
// and boot the line (ETG.1000.4 §5.4: a BRD's working counter is the number of slaves it reached).
// Skipped without root. Also: what the binary says about an interface it cannot open (no root
// needed).
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "tests/ethercat_simtool/support.hpp"
#include "tests/support/netns.hpp"
#include "tests/support/tool_process.hpp"

namespace drivegate::ethercat::sim {
namespace {

using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::VethPair;

std::filesystem::path write_config(const std::string& name, const std::string& yaml) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("drivegate-ecat-sim-test-" + std::to_string(::getpid()) + "-" + name + ".yaml");
  std::ofstream(path) << yaml;
  return path;
}

// drivegate-sim with pipes on stdin, stdout and stderr (tests/support/tool_process.hpp).
class SimProcess : public drivegate::test::ToolProcess {
 public:
  explicit SimProcess(const std::vector<std::string>& args) : ToolProcess(DRIVEGATE_SIM_EXE, args) {}
};

// The part of a status answer about BUS:K, up to its `;`.
std::string item(const std::string& status, const std::string& slave) {
  const auto at = status.find(" " + slave + " ");
  if (at == std::string::npos) return {};
  return status.substr(at + 1, status.find(';', at) - at - 1);
}

class EthercatSimProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_a_ = std::make_unique<NetNamespace>();
    ns_b_ = std::make_unique<NetNamespace>();
    veth_ = std::make_unique<VethPair>(ns_a_.get(), ns_b_.get());
    // The gateway's config names its own end (A); the simulator is told its end (B).
    config_ = write_config("veth", test::three_io_config(veth_->a()));
    {
      const NetnsScope in(*ns_b_);
      sim_ = std::make_unique<SimProcess>(std::vector<std::string>{config_.string(), "--interface", veth_->b()});
    }
    RawSocketOptions o;
    o.interface = veth_->a();
    master_link_ = std::make_unique<RawSocketLink>(o);
    const NetnsScope in(*ns_a_);
    master_link_->open();
  }
  void TearDown() override {
    sim_.reset();
    if (!config_.empty()) std::filesystem::remove(config_);
  }

  std::unique_ptr<NetNamespace> ns_a_;
  std::unique_ptr<NetNamespace> ns_b_;
  std::unique_ptr<VethPair> veth_;
  std::filesystem::path config_;
  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<RawSocketLink> master_link_;
};

TEST_F(EthercatSimProcess, ConsoleFaultsAsTheMasterSeesThem) {
  const auto ready = sim_->line();
  ASSERT_TRUE(ready) << sim_->error_text();
  EXPECT_EQ(*ready, "drivegate-sim: 3 slaves on ethercat " + veth_->b() + " (bus ec0)");
  test::TestMaster master(*master_link_);
  EXPECT_EQ(master.count(3), 3);
  ASSERT_TRUE(master.boot(test::kThreeIo)) << master.line_boot().line_text();
  const std::string booted = sim_->command("status");
  EXPECT_EQ(item(booted, "ec0:1").rfind("ec0:1 generic-io station=0x1001 state=PRE-OP code=0x0000 frames=", 0), 0U)
      << booted;
  EXPECT_EQ(item(booted, "ec0:3").rfind("ec0:3 generic-io station=0x1003 state=PRE-OP code=0x0000 frames=", 0), 0U)
      << booted;

  // Power loss: slave 2 and the one behind it vanish from the count.
  EXPECT_EQ(sim_->command("power-off 2"), "ok power-off ec0:2");
  EXPECT_EQ(master.count(3), 1);
  EXPECT_EQ(item(sim_->command("status"), "ec0:2"), "ec0:2 generic-io off");
  // Power back: counted again, in INIT with station address 0 (ETG.1000.6 §5.3: a slave boots into
  // INIT), while slave 3, powered throughout, keeps PRE-OP.
  EXPECT_EQ(sim_->command("power-on 2"), "ok power-on ec0:2");
  EXPECT_EQ(master.count(3), 3);
  EXPECT_EQ(master.al_status(1), 0x0001);
  EXPECT_EQ(master.al_status(2), 0x0002);
  EXPECT_EQ(item(sim_->command("status"), "ec0:2").rfind("ec0:2 generic-io station=0x0000 state=INIT code=0x0000 ", 0), 0U);

  // Cable break after slave 1: one slave left in the count; mended: three.
  EXPECT_EQ(sim_->command("break-after 1"), "ok break-after ec0:1");
  EXPECT_EQ(master.count(3), 1);
  EXPECT_EQ(sim_->command("mend"), "ok mend ec0");
  EXPECT_EQ(master.count(3), 3);

  // Dropped and corrupted frames do not come back.
  EXPECT_EQ(sim_->command("drop 1"), "ok drop ec0 1");
  EXPECT_FALSE(master.count());
  EXPECT_EQ(sim_->command("corrupt 1"), "ok corrupt ec0 1");
  EXPECT_FALSE(master.count());
  EXPECT_EQ(master.count(), 3);

  // Stuck: a fresh boot reaches PRE-OP, then slave 3 refuses SAFE-OP with the code given, and
  // LineBoot reports it.
  EXPECT_EQ(sim_->command("stick 3 PRE-OP 0x001A"), "ok stick ec0:3 PRE-OP 0x001A (synchronization error)");
  ASSERT_TRUE(master.boot(test::kThreeIo)) << master.line_boot().line_text();
  const SlaveReport r = master.transition(2, AlState::SafeOp);
  EXPECT_EQ(r.status, SlaveStatus::Failed);
  EXPECT_EQ(r.al_code, 0x001A);
  EXPECT_NE(r.text.view().find("0x001A"), std::string_view::npos) << r.text.view();
  EXPECT_EQ(sim_->command("unstick 3"), "ok unstick ec0:3");

  EXPECT_EQ(sim_->command("power-off 4"), "error: no simulated EtherCAT slave 4 (the line has 3)");
  EXPECT_EQ(sim_->stop(), 0);
}

// One drivegate-sim for both bus types of a config: shared verbs go to the bus type that has the
// target, and a target both have must be named with its bus.
TEST_F(EthercatSimProcess, ServesACanopenBusBesideTheEthercatLine) {
  sim_.reset();
  std::string yaml = test::three_io_config(veth_->a());
  yaml += R"(  - name: can0
    type: canopen
    cycle_time: 4ms
    options: { transport: udp-multicast, interface: 127.0.0.1, port: 15999 }
axes:
  - { name: m1, bus: can0, address: 1, device: kollmorgen-akd, mechanics: { encoder_counts_per_rev: 1048576 } }
  - { name: m5, bus: can0, address: 5, device: kollmorgen-akd, mechanics: { encoder_counts_per_rev: 1048576 } }
)";
  std::ofstream(config_) << yaml;
  {
    const NetnsScope in(*ns_b_);
    sim_ = std::make_unique<SimProcess>(std::vector<std::string>{config_.string(), "--interface", veth_->b()});
  }
  EXPECT_EQ(sim_->line(), "drivegate-sim: 3 slaves on ethercat " + veth_->b() + " (bus ec0)") << sim_->error_text();
  EXPECT_EQ(sim_->line(), "drivegate-sim: 2 nodes on udp-multicast 239.74.163.2:15999");
  test::TestMaster master(*master_link_);
  EXPECT_EQ(master.count(3), 3);

  EXPECT_EQ(sim_->command("power-off 5"), "ok power-off node 5");
  EXPECT_EQ(sim_->command("power-off 3"), "ok power-off ec0:3");
  EXPECT_EQ(master.count(3), 2);
  EXPECT_EQ(sim_->command("power-off 1"), "error: 1 is a CANopen node and an EtherCAT position: name it as BUS:1");
  EXPECT_EQ(sim_->command("power-off ec0:1"), "ok power-off ec0:1");
  EXPECT_EQ(sim_->command("power-on can0:5"), "ok power-on node 5");
  EXPECT_EQ(sim_->command("corrupt 1"), "ok corrupt ec0 1");
  EXPECT_EQ(sim_->command("corrupt 1 ec0"), "ok corrupt ec0 1");
  EXPECT_EQ(sim_->command("corrupt 1 2"), "ok corrupt node 1");
  const std::string status = sim_->command("status");
  EXPECT_EQ(status.rfind("status: can0:1 akd ", 0), 0U) << status;
  EXPECT_EQ(item(status, "ec0:1"), "ec0:1 generic-io off") << status;
  EXPECT_EQ(sim_->stop(), 0);
}

TEST(EthercatSimTool, AnInterfaceItCannotOpenIsNamed) {
  const auto config = write_config("nosuch", test::three_io_config("dgtnosuch0"));
  SimProcess sim({config.string()});
  EXPECT_EQ(sim.stop(false), 1);
  const std::string err = sim.error_text();
  std::filesystem::remove(config);
  EXPECT_EQ(err.rfind("drivegate-sim: ethercat: ", 0), 0U) << err;
  EXPECT_NE(err.find("dgtnosuch0"), std::string::npos) << err;
}

TEST(EthercatSimTool, ALineWithAGapIsRefused) {
  const auto config = write_config("gap", R"(gateway: { name: t }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { interface: eth1 }
    io: [{ name: a, position: 2 }]
)");
  SimProcess sim({config.string()});
  EXPECT_EQ(sim.stop(false), 1);
  const std::string err = sim.error_text();
  std::filesystem::remove(config);
  // The config check of the ethercat bus type refuses the gap before a line is built.
  EXPECT_EQ(err, "drivegate-sim: " + config.string() +
                     ":3:5: buses[0]: bus 'ec0': position 1 has neither an axis nor an io: entry; list every slave up "
                     "to the last configured one (the frame passes them all, and each must be known to be started)\n");
}

}  // namespace
}  // namespace drivegate::ethercat::sim
