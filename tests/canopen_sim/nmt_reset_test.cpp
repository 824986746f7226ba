// NMT resets per persona: what Reset Node and Reset Communication restore, and whether a boot-up
// follows.
#include <gtest/gtest.h>

#include "tests/canopen_sim/sim_test_support.hpp"

namespace drivegate::canopen::sim::test {
namespace {

// Changes to communication, application and manufacturer objects, and an enabled drive.
void change_everything(Drive& d) {
  ASSERT_EQ(d.write({0x1017, 0}, 50, 2), 0U);
  ASSERT_EQ(d.write({0x1800, 1}, 0xC0000181U, 4), 0U);  // part 1 §12.6 step 1
  ASSERT_EQ(d.write({0x1A00, 0}, 0, 1), 0U);
  ASSERT_EQ(d.write({0x6081, 0}, 1234, 4), 0U);
  d.enable();
  ASSERT_EQ(d.statusword() & 0x6F, 0x27);
}

TEST(NmtReset, ResetNodeRestoresCommunicationAndApplicationObjects) {
  Drive d(akd(1));
  d.boot();
  const auto profile_velocity = d.value({0x6081, 0});
  ASSERT_EQ(d.write({0x36E9, 0}, 0x315, 4), 0U);
  change_everything(d);

  const auto frames = d.send(nmt(NmtCommand::ResetNode, 1));
  ASSERT_FALSE(frames.empty());
  EXPECT_TRUE(is_frame(frames[0], 0x701, {0x00}));
  EXPECT_EQ(d.node.nmt_state(), NmtState::PreOperational);
  // Communication and mapping back to the factory values (AKD part 1 quirk 10)...
  EXPECT_EQ(d.value({0x1017, 0}), 0U);
  EXPECT_EQ(d.value({0x1800, 1}), 0x181U);
  EXPECT_EQ(d.value({0x1A00, 0}), 1U);
  // ...and the application: the controlword is 0, so the drive leaves Operation enabled.
  EXPECT_EQ(d.value({0x6081, 0}), profile_velocity);
  EXPECT_EQ(d.value({0x36E9, 0}), 0U);
  EXPECT_EQ(d.value({0x6040, 0}), 0U);
  d.run(5ms);
  EXPECT_EQ(d.statusword() & 0x4F, 0x40);
}

TEST(NmtReset, ResetCommunicationKeepsTheApplication) {
  Drive d(generic(1));
  d.boot();
  change_everything(d);
  const auto frames = d.send(nmt(NmtCommand::ResetCommunication, 0));  // all nodes
  ASSERT_FALSE(frames.empty());
  EXPECT_TRUE(is_frame(frames[0], 0x701, {0x00}));
  EXPECT_EQ(d.value({0x1017, 0}), 0U);
  EXPECT_EQ(d.value({0x1800, 1}), 0x181U);
  EXPECT_EQ(d.value({0x1A00, 0}), 2U);  // the power-on mapping (here: the profile's)
  EXPECT_EQ(d.value({0x6081, 0}), 1234U);
  d.run(5ms);
  EXPECT_EQ(d.statusword() & 0x6F, 0x27);  // still enabled
}

TEST(NmtReset, Sd6DoesNotRepeatItsBootUp) {
  Drive d(sd6(5));
  ASSERT_TRUE(is_frame(d.boot().at(0), 0x705, {0x00}));
  ASSERT_EQ(d.write({0x100C, 0}, 100, 2), 0U);
  for (const auto cmd : {NmtCommand::ResetNode, NmtCommand::ResetCommunication}) {
    d.send(nmt(NmtCommand::Start, 5));
    const auto frames = d.send(nmt(cmd, 5));
    EXPECT_TRUE(on_id(frames, 0x705).empty()) << to_string(cmd);  // quirk 9
    EXPECT_EQ(d.node.nmt_state(), NmtState::PreOperational);
    EXPECT_EQ(d.value({0x100C, 0}), 0U);
    EXPECT_EQ(d.value({0x1600, 3}), 0x607A0020U);  // the commissioned mapping survives
  }
}

TEST(NmtReset, OtherNodesCommandsAreIgnored) {
  Drive d(generic(1));
  d.boot();
  ASSERT_EQ(d.write({0x1017, 0}, 50, 2), 0U);
  EXPECT_TRUE(d.send(nmt(NmtCommand::ResetNode, 2)).empty());
  EXPECT_EQ(d.value({0x1017, 0}), 50U);
  EXPECT_EQ(d.node.nmt_state(), NmtState::PreOperational);
}

TEST(NmtReset, StoppedNodeAnswersNoSdoButHeartbeats) {
  Drive d(generic(1));
  d.boot();
  ASSERT_EQ(d.write({0x1017, 0}, 10, 2), 0U);
  d.send(nmt(NmtCommand::Stop, 1));
  EXPECT_TRUE(on_id(d.send(make_frame(0x601, sdo_upload_request({0x1000, 0}))), 0x581).empty());
  EXPECT_EQ(d.node.counters().ignored_state, 1U);
  const auto hb = on_id(d.run(25ms), 0x701);
  ASSERT_EQ(hb.size(), 2U);
  EXPECT_TRUE(is_frame(hb[0], 0x701, {0x04}));
  // A SYNC is not served either: no synchronous TPDO.
  EXPECT_TRUE(on_id(d.send(sync_frame()), 0x181).empty());
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
