// The endpoint over a veth pair between two network namespaces the test creates (and always
// removes; skipped without root): end A is the master's port (RawSocketLink + Transactions +
// LineBoot, the master's own engines), end B carries the simulated line of a config, served by a
// SimEndpoint on a RawSocketLink in a thread of its own.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <thread>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/sim/sim_endpoint.hpp"
#include "tests/ethercat_simtool/support.hpp"
#include "tests/support/netns.hpp"

namespace drivegate::ethercat::sim {
namespace {

using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::VethPair;

std::unique_ptr<RawSocketLink> open_in(const NetNamespace& ns, const std::string& iface) {
  RawSocketOptions o;
  o.interface = iface;
  auto link = std::make_unique<RawSocketLink>(std::move(o));
  const NetnsScope in(ns);
  link->open();
  return link;
}

class EthercatEndpointVeth : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_a_ = std::make_unique<NetNamespace>();
    ns_b_ = std::make_unique<NetNamespace>();
    veth_ = std::make_unique<VethPair>(ns_a_.get(), ns_b_.get());
  }
  void TearDown() override {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  void serve(SimEndpoint& endpoint) {
    thread_ = std::thread([this, &endpoint] { run_endpoint(endpoint, stop_); });
  }

  // Members go in reverse order: the pair before its namespaces.
  std::unique_ptr<NetNamespace> ns_a_;
  std::unique_ptr<NetNamespace> ns_b_;
  std::unique_ptr<VethPair> veth_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST_F(EthercatEndpointVeth, TheMastersLineBootBringsThreeIoSlavesToPreOp) {
  const config::Plan plan = test::plan_of(test::three_io_config(veth_->a()));
  const auto line = build_line(plan.buses.at(0));
  auto wire = open_in(*ns_b_, veth_->b());
  SimEndpoint endpoint(*wire, *line);
  auto master_link = open_in(*ns_a_, veth_->a());
  serve(endpoint);

  test::TestMaster master(*master_link);
  EXPECT_EQ(master.count(3), 3);
  ASSERT_TRUE(master.boot(test::kThreeIo)) << master.line_boot().line_text();
  for (std::size_t k = 0; k < 3; ++k) {
    const SlaveReport& r = master.line_boot().slave(k);
    EXPECT_EQ(r.status, SlaveStatus::Ready) << k << ": " << r.text.view();
    EXPECT_EQ(r.state, AlState::PreOp);
    EXPECT_EQ(r.station, 0x1001 + k);
  }
  EXPECT_EQ(master.line_boot().sii(2).header.identity, (SiiIdentity{0x99, 0x1000, 1, 3}));
  stop_ = true;
  thread_.join();
  // Read after the thread ended: the line belongs to it while it runs.
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(line->slave(k).esc->state(), AlState::PreOp);
  EXPECT_GT(endpoint.counters().frames_in, 10U);
  EXPECT_EQ(endpoint.counters().frames_out, endpoint.counters().frames_in);
  EXPECT_EQ(endpoint.counters().not_sent, 0U);
  EXPECT_GT(endpoint.counters().ticks, 0U);
  EXPECT_EQ(line->slave(0).frames_seen, endpoint.counters().frames_in);
}

}  // namespace
}  // namespace drivegate::ethercat::sim
