// The EtherCAT bus on a simulated line: start-up to OP, the axes disabled; first smoke test.
#include <gtest/gtest.h>

#include "tests/ethercat_bus/bus_harness.hpp"

namespace drivegate::ethercat::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::LinkState;
using core::ReplyStatus;

TEST(EthercatBus, ReachesOpWithTheAxesDisabled) {
  EcatHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.details() << h.events_text();
  EXPECT_EQ(h.esr.esc->state(), AlState::Op);
  EXPECT_EQ(h.panel_esc->state(), AlState::Op);
  EXPECT_EQ(h.gen.esc->state(), AlState::Op);
  EXPECT_EQ(h.snap("esr").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.snap("gen").state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.bus->link_detail(h.axis("esr")), "slave 1 (0x1001, ESR TrioDrive D/ES): in OP");
}

}  // namespace
}  // namespace drivegate::ethercat::test
