// The simulated devices on a real port: a PnSimNetwork (an AKD at 192.168.0.11, a generic IO
// device at .12) behind a RawSocketLink and UdpEndpoints on one end of a veth pair, the
// controller's DcpClient and CmClient with its cyclic engines on the other, in namespaces the test
// makes and removes; real time. Skipped without root.
#include <poll.h>

#include <gtest/gtest.h>

#include "adapters/link/raw_socket_link.hpp"
#include "adapters/link/udp_endpoint.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/sim/pn_sim_link.hpp"
#include "tests/profinet_sim/veth_controller.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::profinet::test {
namespace {

using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::VethPair;

class PnSimVeth : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_ctl_ = std::make_unique<NetNamespace>();
    ns_dev_ = std::make_unique<NetNamespace>();
    veth_ = std::make_unique<VethPair>(ns_ctl_.get(), ns_dev_.get());
    // The controller's end has the controller's MAC; the simulator's end takes every device's.
    veth_->set(VethPair::End::A, {"address", "02:00:00:00:00:01"});
    veth_->set(VethPair::End::B, {"promisc", "on"});
    ASSERT_TRUE(ns_ctl_->ip({"addr", "add", "192.168.0.1/24", "dev", veth_->a()}).ok());
    for (const char* a : {"192.168.0.11/24", "192.168.0.12/24"}) {
      ASSERT_TRUE(ns_dev_->ip({"addr", "add", a, "dev", veth_->b()}).ok());
    }
    akd_ = std::make_unique<AkdPersona>(AkdPersonaConfig{});
    io_ = std::make_unique<GenericIoPersona>(GenericIoPersonaConfig{
        {{0, 0, 0x10, {{1, 0x10, 0, 0}}}, {0, 1, 0x20, {{1, 0x21, 2, 0}}}}, 0x0042, "IO-1", "1"});
    net_.add(device_config(1, "drive-a", suite(11)), *akd_);
    net_.add(device_config(2, "io-b", suite(12)), *io_);

    link::RawSocketOptions o;
    o.interface = veth_->b();
    device_link_ = std::make_unique<link::RawSocketLink>(kFrameRules, o);
    const std::string dev_if = veth_->b();
    runner_ = std::make_unique<PnSimLinkRunner>(net_, *device_link_, [dev_if](const link::Ipv4Endpoint& local) {
      link::UdpOptions u = rpc_udp_options(dev_if, local.port);
      u.address = local.address;
      return std::make_unique<link::UdpEndpoint>(u);
    });
    controller_ = std::make_unique<VethController>(veth_->a());
    {
      const NetnsScope in(*ns_dev_);
      runner_->open();
    }
    const NetnsScope in(*ns_ctl_);
    controller_->open();
  }

  // Runs both sides until `done` or 10 s, waiting for traffic at most 1 ms at a time.
  bool run_until(const std::function<bool()>& done) {
    std::vector<pollfd> fds;
    for (const int fd : runner_->wait_fds()) fds.push_back({fd, POLLIN, 0});
    for (const int fd : controller_->wait_fds()) fds.push_back({fd, POLLIN, 0});
    const core::SteadyClock clock;
    for (const core::TimePoint end = clock.now() + 10s; clock.now() < end;) {
      const core::TimePoint now = clock.now();
      controller_->poll(now);
      runner_->run_once(now);
      if (done()) return true;
      (void)::poll(fds.data(), fds.size(), 1);
    }
    return done();
  }

  std::unique_ptr<NetNamespace> ns_ctl_, ns_dev_;
  std::unique_ptr<VethPair> veth_;
  std::unique_ptr<AkdPersona> akd_;
  std::unique_ptr<GenericIoPersona> io_;
  PnSimNetwork net_;
  std::unique_ptr<link::RawSocketLink> device_link_;
  std::unique_ptr<PnSimLinkRunner> runner_;
  std::unique_ptr<VethController> controller_;
  std::unique_ptr<ArPlan> plan_;
};

TEST_F(PnSimVeth, IdentifyAndConnectAcrossARealPort) {
  DcpClient& dcp = controller_->dcp;
  std::array<DcpStation, 8> found{};
  const DcpRequestId id = dcp.identify_all(found, 1);
  ASSERT_TRUE(run_until([&] { return dcp.result(id).status == DcpRequestStatus::Done; }));
  ASSERT_EQ(dcp.stations(id).size(), 2U);

  plan_ = std::make_unique<ArPlan>(akd_plan(1, 4, 4), ip_of(11), device_mac(1), 0);
  ASSERT_TRUE(controller_->connect(*plan_, core::SteadyClock{}.now()));
  CmClient& cm = controller_->cm();
  ASSERT_TRUE(run_until([&] { return cm.state() == CmClientState::DataExchange || cm.state() == CmClientState::Failed; }));
  ASSERT_EQ(cm.state(), CmClientState::DataExchange) << cm.reason();
  ASSERT_TRUE(run_until([&] { return plan_->consumer->counters().frames >= 5; })) << plan_->consumer->reason();
  EXPECT_EQ(plan_->consumer->state(), RtConsumerState::Running);
  EXPECT_EQ(net_.device(0).ar_state(), CmServerState::DataExchange);
  const RtConsumer* output = net_.device(0).output_cr();
  ASSERT_NE(output, nullptr);
  EXPECT_EQ(output->state(), RtConsumerState::Running);
  EXPECT_EQ(runner_->port_error(), "");
}

}  // namespace
}  // namespace drivegate::profinet::test
