// Device control through the master: enable walk, timeouts, quick stop, disable, fault reset edge.
#include <gtest/gtest.h>

#include "tests/cia402/master_harness.hpp"

namespace drivegate::cia402::test {
namespace {

using core::CommandKind;

TEST(EnableWalk, OneTransitionPerCycleAsInTheManual) {
  Harness h;
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0000);  // nothing enables unless commanded
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  // AKD digest §12.2: 0x0006 -> 0x0221, 0x0007 -> 0x0233, 0x000F -> 0x0237. The drive answers one
  // cycle late, and the master repeats the same command until the statusword shows the new state.
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0006);
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0006);
  EXPECT_EQ(h.cycle(kSwReady), 0x0007);
  EXPECT_EQ(h.cycle(kSwReady), 0x0007);
  EXPECT_EQ(h.cycle(kSwSwitchedOn), 0x000F);
  EXPECT_FALSE(h.sink.done(1));
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_TRUE(h.sink.done(1));
  EXPECT_EQ(h.master.feedback().state, core::AxisState::OperationEnabled);
}

TEST(EnableWalk, NeverSkipsAStateEvenWhenTheDriveJumps) {
  Harness h;
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0006);
  // Whatever the state, the master sends the one command that leaves it.
  EXPECT_EQ(h.cycle(kSwSwitchedOn), 0x000F);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_TRUE(h.sink.done(1));
}

TEST(EnableWalk, FromQuickStopActiveGoesThroughSwitchOnDisabled) {
  Harness h;
  h.cycle(kSwQuickStop);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  EXPECT_EQ(h.cycle(kSwQuickStop), 0x0000);
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0006);
}

TEST(EnableWalk, StepTimeoutNamesTheStuckState) {
  MasterSettings s;
  s.enable_step_timeout = 100ms;
  Harness h(s);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  h.cycle(kSwSwitchOnDisabled);
  for (int i = 0; i < 50; ++i) h.cycle(kSwReady);  // progress resets the step timer
  EXPECT_TRUE(h.sink.failure(1).empty());
  for (int i = 0; i < 60; ++i) h.cycle(kSwReady);  // hardware enable missing: stuck in Ready
  const std::string why = h.sink.failure(1);
  EXPECT_NE(why.find("ready_to_switch_on"), std::string::npos) << why;
  EXPECT_NE(why.find("100 ms"), std::string::npos) << why;
  EXPECT_NE(why.find("0x0007"), std::string::npos) << why;
  EXPECT_EQ(h.cw(), 0x0000);  // a failed enable leaves the drive disabled
}

TEST(EnableWalk, DriveFallingBackFailsTheEnable) {
  Harness h;
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwReady);
  h.cycle(kSwSwitchedOn);
  h.cycle(kSwSwitchOnDisabled);  // hardware enable dropped (AKD digest §3.7 item 5)
  EXPECT_NE(h.sink.failure(1).find("fell back from switched_on to switch_on_disabled"), std::string::npos)
      << h.sink.failure(1);
  EXPECT_EQ(h.cw(), 0x0000);
}

TEST(EnableWalk, RejectedInFaultWithAnActionableReason) {
  Harness h;
  h.cycle(kSwFault);
  const auto a = h.submit(command(1, CommandKind::Enable));
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "axis is in fault: send fault_reset first");
}

TEST(EnableWalk, NothingIsAcceptedBeforeTheFirstStatus) {
  Harness h;
  const auto a = h.submit(command(1, CommandKind::Enable));
  EXPECT_FALSE(a.accepted);
  EXPECT_NE(a.reason.view().find("no status"), std::string_view::npos);
}

TEST(QuickStop, Transition11ThenHoldsBit2Low) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::QuickStop)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x0002);
  EXPECT_FALSE(h.sink.done(2));
  EXPECT_EQ(h.cycle(kSwQuickStop), 0x0002);
  EXPECT_TRUE(h.sink.done(2));
  EXPECT_EQ(h.cycle(kSwQuickStop), 0x0002);  // no transition 16 back to enabled by itself
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0002);
}

TEST(QuickStop, AbortsTheMoveInFlight) {
  Harness h;
  h.enable();
  auto move = command(5, CommandKind::Move);
  move.target_position = 1000;
  ASSERT_TRUE(h.submit(move).accepted);
  h.cycle(kSwEnabled);
  ASSERT_TRUE(h.submit(command(6, CommandKind::QuickStop)).accepted);
  EXPECT_EQ(h.sink.failure(5), "aborted by a quick_stop command");
  EXPECT_EQ(h.cycle(kSwEnabled), 0x0002);  // bit 4 dropped with the move
}

TEST(Disable, DisableVoltageUntilSwitchOnDisabled) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::Disable)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x0000);
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0000);
  EXPECT_TRUE(h.sink.done(2));
}

TEST(Disable, SupersedesAnEnableInFlight) {
  Harness h;
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(2, CommandKind::Disable)).accepted);
  EXPECT_EQ(h.sink.failure(1), "aborted by a disable command");
  EXPECT_EQ(h.cycle(kSwReady), 0x0000);
}

TEST(FaultReset, RisingEdgeOnBit7ThenClearedWhenTheDriveLeavesFault) {
  Harness h;
  h.io.set(obj::kErrorCode.id, 0x2310);
  h.cycle(kSwFault);
  ASSERT_TRUE(h.submit(command(3, CommandKind::FaultReset)).accepted);
  EXPECT_EQ(h.cycle(kSwFault), 0x0080);  // bit 7 was low: the edge can go out at once
  EXPECT_EQ(h.cycle(kSwFault), 0x0080);  // held while the drive is still in fault
  EXPECT_FALSE(h.sink.done(3));
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0000);  // cleared again (AKD digest §3.2 #15)
  EXPECT_TRUE(h.sink.done(3));
  EXPECT_EQ(h.sink.count(core::EventKind::FaultCleared), 1U);
  // Restart the enable walk from 0x0006 afterwards.
  ASSERT_TRUE(h.submit(command(4, CommandKind::Enable)).accepted);
  EXPECT_EQ(h.cycle(kSwSwitchOnDisabled), 0x0006);
}

TEST(FaultReset, SendsBit7LowFirstWhenItWasHigh) {
  Harness h;
  h.cycle(kSwFault);
  ASSERT_TRUE(h.submit(command(3, CommandKind::FaultReset)).accepted);
  EXPECT_EQ(h.cycle(kSwFault), 0x0080);
  ASSERT_TRUE(h.submit(command(4, CommandKind::FaultReset)).accepted);
  EXPECT_EQ(h.sink.failure(3), "superseded by a newer fault_reset command");
  EXPECT_EQ(h.cycle(kSwFault), 0x0000);  // 1 -> 0 first ...
  EXPECT_EQ(h.cycle(kSwFault), 0x0080);  // ... so that this is a 0 -> 1 edge
}

TEST(FaultReset, TimesOutWhenTheCauseIsStillPresent) {
  MasterSettings s;
  s.enable_step_timeout = 50ms;
  Harness h(s);
  h.cycle(kSwFault);
  ASSERT_TRUE(h.submit(command(3, CommandKind::FaultReset)).accepted);
  for (int i = 0; i < 60; ++i) h.cycle(kSwFault);
  EXPECT_NE(h.sink.failure(3).find("still in fault"), std::string::npos) << h.sink.failure(3);
  EXPECT_EQ(h.cw(), 0x0000);  // bit 7 cleared after the timeout
}

TEST(FaultReset, WaitsForTheFaultReactionToEnd) {
  Harness h;
  h.cycle(0x021F);  // fault reaction active
  ASSERT_TRUE(h.submit(command(3, CommandKind::FaultReset)).accepted);
  EXPECT_EQ(h.cycle(0x021F), 0x0000);
  EXPECT_EQ(h.cycle(kSwFault), 0x0080);
}

TEST(FaultReset, CompletesAtOnceWhenThereIsNoFault) {
  Harness h;
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(3, CommandKind::FaultReset)).accepted);
  EXPECT_TRUE(h.sink.done(3));
}

}  // namespace
}  // namespace drivegate::cia402::test
