// Profile position mode on the drive side [AKD digest §10; nord §5.1].
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/cia402_sim/drive_harness.hpp"

namespace drivegate::cia402::sim::test {
namespace {

constexpr std::uint16_t kAck = 0x1000;
constexpr std::uint16_t kReached = 0x0400;

class ProfilePosition : public ::testing::Test {
 protected:
  void SetUp() override { h.enable(op_mode::kProfilePosition); }
  // Raises new-set-point with the given extra bits and lowers it again after the acknowledge.
  void start(std::int32_t target, std::uint16_t extra = 0) {
    h.set(obj::kTargetPosition, target);
    h.cw(static_cast<std::uint16_t>(0x001F | extra));
    h.step();
    ASSERT_NE(h.sw() & kAck, 0);
    h.cw(static_cast<std::uint16_t>(0x000F | extra));
  }
  DriveHarness h;
};

TEST_F(ProfilePosition, SetpointHandshakeAndTargetReached) {
  EXPECT_NE(h.sw() & kReached, 0);  // nothing to do: at the target
  h.set(obj::kTargetPosition, 50000);
  h.cw(0x001F);
  h.step();
  EXPECT_EQ(h.sw() & 0x1637, 0x1237);  // acknowledged, moving
  h.step(5);
  EXPECT_NE(h.sw() & kAck, 0);  // acknowledge stays while bit 4 stays
  h.cw(0x000F);
  h.step();
  EXPECT_EQ(h.sw() & kAck, 0);  // cleared with bit 4: ready for the next set-point
  // 10 rev/s, 100 rev/s^2, 5 rev: 0.1 s + 0.4 s + 0.1 s.
  const int steps = h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_GT(steps, 550);
  EXPECT_LT(steps, 700);
  EXPECT_NEAR(h.drive.position(), 50000.0, 10.0);
  EXPECT_EQ(h.sw() & 0x1637, 0x0637);
  EXPECT_EQ(h.get(obj::kPositionDemand), 50000);
}

TEST_F(ProfilePosition, ProfileVelocityLimitsTheCruise) {
  h.set(obj::kProfileVelocity, 20000);
  start(20000);
  h.step(300);
  EXPECT_NEAR(static_cast<double>(h.get(obj::kVelocityActual)), 20000.0, 200.0);
  h.set(obj::kMaxProfileVelocity, 5000);  // 607Fh caps 6081h for the next set-point
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  start(0);
  h.step(300);
  EXPECT_NEAR(static_cast<double>(h.get(obj::kVelocityActual)), -5000.0, 100.0);
}

TEST_F(ProfilePosition, NewSetpointOnlyOnRisingEdge) {
  start(10000);
  h.cw(0x001F);  // bit 4 held high for a long time: one set-point only
  h.step();
  h.set(obj::kTargetPosition, 90000);
  h.step(400);
  EXPECT_NEAR(h.drive.position(), 10000.0, 10.0);
}

TEST_F(ProfilePosition, SetpointWhileAcknowledgeHighIsIgnored) {
  h.set(obj::kTargetPosition, 10000);
  h.cw(0x001F);
  h.step();
  h.cw(0x000F);  // the drive sees the falling edge only in this step
  h.set(obj::kTargetPosition, 80000);
  h.cw(0x001F);  // bit 4 high again before the drive lowered the acknowledge: no edge seen
  h.step(500);
  EXPECT_NEAR(h.drive.position(), 10000.0, 10.0);
}

TEST_F(ProfilePosition, ChangeSetImmediatelyAbortsTheRunningJob) {
  start(100000, 0x0020);
  h.step(200);
  ASSERT_GT(h.drive.velocity(), 50000.0);
  start(20000, 0x0020);
  double peak = h.drive.position();
  h.run_until([&] {
    peak = std::max(peak, h.drive.position());
    return (h.sw() & kReached) != 0;
  });
  EXPECT_LT(peak, 40000.0);  // turned round long before 100000
  EXPECT_NEAR(h.drive.position(), 20000.0, 10.0);
}

TEST_F(ProfilePosition, QueuedSetpointRunsAfterTheFirstTarget) {
  start(30000);
  h.step(50);
  h.set(obj::kTargetPosition, 60000);
  h.cw(0x001F);
  h.step();
  ASSERT_NE(h.sw() & kAck, 0);
  h.cw(0x000F);
  h.step(5);
  EXPECT_NE(h.sw() & kAck, 0) << "acknowledge held while the job waits in the buffer";
  bool stopped_at_first = false;
  h.run_until([&] {
    if (std::abs(h.drive.position() - 30000.0) < 50.0 && std::abs(h.drive.velocity()) < 2000.0) {
      stopped_at_first = true;
    }
    return (h.sw() & kAck) == 0;
  });
  EXPECT_TRUE(stopped_at_first);
  EXPECT_EQ(h.sw() & kReached, 0);  // the second job is running
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_NEAR(h.drive.position(), 60000.0, 10.0);
}

TEST_F(ProfilePosition, RelativeMoveAddsToTheLastTarget) {
  start(50000);
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  start(-20000, 0x0040);
  h.step();
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_NEAR(h.drive.position(), 30000.0, 10.0);
}

TEST_F(ProfilePosition, HaltStopsHoldsAndResumes) {
  start(80000);
  h.step(300);
  h.cw(0x010F);
  h.run_until([&] { return (h.sw() & kReached) != 0; });  // target reached = halted at standstill
  const double stopped = h.drive.position();
  EXPECT_LT(stopped, 70000.0);
  h.step(100);
  EXPECT_NEAR(h.drive.position(), stopped, 5.0);
  h.cw(0x000F);  // the set-point was kept
  h.step(5);
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_NEAR(h.drive.position(), 80000.0, 10.0);
}

TEST_F(ProfilePosition, SoftwareLimitsClampTheTarget) {
  h.set(obj::kSoftwareLimitMin, -1000);
  h.set(obj::kSoftwareLimitMax, 20000);
  start(50000);
  h.run_until([&] { return (h.sw() & kReached) != 0; });
  EXPECT_NEAR(h.drive.position(), 20000.0, 10.0);
}

TEST_F(ProfilePosition, FollowingErrorRaisesFault8611) {
  h.set(obj::kFollowingErrorWindow, 500);
  h.set(obj::kFollowingErrorTimeout, 20);
  h.drive.set_motor_blocked(true);
  start(50000);
  bool warned = false;
  const int steps = h.run_until([&] {
    warned = warned || (h.sw() & 0x2000) != 0;
    return h.state() != DriveState::OperationEnabled;
  });
  EXPECT_TRUE(warned);  // bit 13 before the fault
  EXPECT_GT(steps, 20);
  EXPECT_EQ(h.state(), DriveState::FaultReactionActive);
  EXPECT_EQ(h.get(obj::kErrorCode), 0x8611);
  // A following error has no lasting cause: the reset works at once.
  h.drive.set_motor_blocked(false);
  h.run_until([&] { return h.state() == DriveState::Fault; });
  h.cw(0x0080);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);
}

TEST_F(ProfilePosition, FollowingErrorMonitoringOffWithZeroWindow) {
  h.set(obj::kFollowingErrorWindow, 0);
  h.drive.set_motor_blocked(true);
  start(50000);
  h.step(500);
  EXPECT_EQ(h.state(), DriveState::OperationEnabled);
}

}  // namespace
}  // namespace drivegate::cia402::sim::test
