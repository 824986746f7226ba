// LineBoot's additions for the bus: several accepted identities per position, any identity, and
// restart_slave() of one slave (after a power loss: re-addressed by position, APWR 0010h) while
// the others stay where they are.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/ethercat/sim/sim_line.hpp"
#include "tests/ethercat_sim/line_exchange.hpp"

namespace drivegate::ethercat {
namespace {

using namespace std::chrono_literals;

constexpr SiiIdentity kA{0x00000099, 0x00001000, 1, 0};
constexpr SiiIdentity kB{0x00000099, 0x00002000, 3, 0};

struct IoLine {
  IoLine() {
    link.open();
    for (const SiiIdentity& id : {kA, kB}) {
      apps.push_back(std::make_unique<sim::GenericIoSlave>(2, 2, id));
      escs.push_back(std::make_unique<sim::EscSlave>(sim::EscConfig{}, apps.back()->sii(), apps.back().get()));
      line.add(*escs.back());
    }
  }
  void cycle(LineBoot& boot) {
    boot.poll(now, tx);
    drivegate::ethercat::test::exchange_over_line(tx, link, line, now);
  }
  void run(LineBoot& boot) {
    for (int i = 0; i < 5000 && boot.status() == LineStatus::Running; ++i) cycle(boot);
  }
  bool busy(const LineBoot& boot, std::size_t k) const { return boot.slave(k).status == SlaveStatus::Busy; }

  MemoryLink link{16};
  sim::SimLine line{link};
  std::vector<std::unique_ptr<sim::GenericIoSlave>> apps;
  std::vector<std::unique_ptr<sim::EscSlave>> escs;
  Transactions tx;
  core::TimePoint now{};
};

TEST(LineBootForTheBus, OtherIdentitiesAndAnyIdentityAreAccepted) {
  IoLine t;
  // Position 2 expects A but also takes B (revision 0: any); without that it is a mismatch.
  const std::array<ExpectedSlave, 2> expected{ExpectedSlave{kA.vendor_id, kA.product_code, 0, "io A"},
                                              ExpectedSlave{kA.vendor_id, kA.product_code, 0, "io A"}};
  {
    auto boot = std::make_unique<LineBoot>(expected, LineBootConfig{});
    boot->start(t.now);
    t.run(*boot);
    EXPECT_FALSE(boot->ok());
    EXPECT_TRUE(boot->slave(1).identity_mismatch());
    EXPECT_NE(boot->slave(1).text.view().find("found vendor 0x00000099 product 0x00002000 revision 0x00000003"),
              std::string_view::npos)
        << boot->slave(1).text.view();
  }
  const std::array<SiiIdentity, 1> also{SiiIdentity{kB.vendor_id, kB.product_code, 0, 0}};
  {
    auto boot = std::make_unique<LineBoot>(expected, LineBootConfig{});
    boot->accept_identities(1, also);
    boot->start(t.now);
    t.run(*boot);
    EXPECT_TRUE(boot->ok()) << boot->slave(1).text.view();
  }
  {
    auto boot = std::make_unique<LineBoot>(expected, LineBootConfig{});
    boot->accept_identities(1, {}, true);
    boot->start(t.now);
    t.run(*boot);
    EXPECT_TRUE(boot->ok()) << boot->slave(1).text.view();
  }
}

TEST(LineBootForTheBus, RestartSlaveReaddressesAPowerCycledSlaveOnly) {
  IoLine t;
  const std::array<ExpectedSlave, 2> expected{ExpectedSlave{kA.vendor_id, kA.product_code, 0, "io A"},
                                              ExpectedSlave{kB.vendor_id, kB.product_code, 0, "io B"}};
  auto boot = std::make_unique<LineBoot>(expected, LineBootConfig{});
  boot->start(t.now);
  t.run(*boot);
  ASSERT_TRUE(boot->ok());
  // Slave 1 taken to INIT by hand: a restart of slave 2 must leave it there.
  ASSERT_TRUE(boot->request_state(0, AlState::Init, t.now));
  for (int i = 0; i < 100 && t.busy(*boot, 0); ++i) t.cycle(*boot);
  ASSERT_EQ(t.escs[0]->state(), AlState::Init) << boot->slave(0).text.view();

  // Slave 2 loses power: back in INIT with station 0. restart_slave() finds no answer at 1002h,
  // writes the station by position and takes it to PRE-OP; slave 1 stays in INIT.
  t.line.power_off(1);
  t.line.power_on(1);
  EXPECT_EQ(t.escs[1]->station_address(), 0);
  ASSERT_TRUE(boot->restart_slave(1, t.now));
  EXPECT_FALSE(boot->restart_slave(1, t.now));  // busy
  for (int i = 0; i < 2000 && t.busy(*boot, 1); ++i) t.cycle(*boot);
  EXPECT_EQ(boot->slave(1).status, SlaveStatus::Ready) << boot->slave(1).text.view();
  EXPECT_EQ(boot->slave(1).state, AlState::PreOp);
  EXPECT_EQ(t.escs[1]->station_address(), 0x1002);
  EXPECT_EQ(t.escs[1]->state(), AlState::PreOp);
  EXPECT_EQ(t.escs[0]->state(), AlState::Init);

  // A slave that kept its address (it left OP by itself) is probed at its station and taken
  // through INIT to PRE-OP again (SII and identity read anew).
  ASSERT_TRUE(boot->restart_slave(0, t.now));
  for (int i = 0; i < 2000 && t.busy(*boot, 0); ++i) t.cycle(*boot);
  EXPECT_EQ(boot->slave(0).status, SlaveStatus::Ready) << boot->slave(0).text.view();
  EXPECT_EQ(t.escs[0]->state(), AlState::PreOp);

  // Nothing at the position: the restart fails at the address step with one sentence.
  t.line.power_off(1);
  ASSERT_TRUE(boot->restart_slave(1, t.now));
  for (int i = 0; i < 2000 && t.busy(*boot, 1); ++i) t.cycle(*boot);
  EXPECT_EQ(boot->slave(1).status, SlaveStatus::Failed);
  EXPECT_EQ(boot->slave(1).step, BootStep::Address);
  EXPECT_EQ(boot->slave(1).text.view(), "slave 2 (0x1002, io B): no answer at position 2 (APWR 0x0010 WKC 0)");
}

}  // namespace
}  // namespace drivegate::ethercat
