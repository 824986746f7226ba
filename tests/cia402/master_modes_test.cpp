// Mode selection and the per-mode handshakes, cycle by cycle against a scripted drive.
#include <gtest/gtest.h>

#include "tests/cia402/master_harness.hpp"

namespace drivegate::cia402::test {
namespace {

using core::CommandKind;
using core::Mode;

core::DriveCommand move(core::CommandId id, std::int32_t target) {
  auto c = command(id, CommandKind::Move);
  c.target_position = target;
  c.profile_velocity = 20000;
  c.immediate = false;
  return c;
}

TEST(ProfilePosition, SetpointHandshakeAsInTheManual) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 36000)).accepted);
  // AKD digest §12.8: 607Ah/6081h, CW 0x001F, SW 0x1237, CW 0x000F, SW 0x0237, SW 0x0637.
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);
  EXPECT_EQ(h.io.value(obj::kTargetPosition.id), 36000);
  EXPECT_EQ(h.io.value(obj::kProfileVelocity.id), 20000);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);  // held until acknowledged
  EXPECT_EQ(h.cycle(kSwEnabledAck), 0x000F);
  EXPECT_EQ(h.cycle(kSwEnabledAck), 0x000F);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_FALSE(h.sink.done(7));
  EXPECT_EQ(h.cycle(kSwEnabledReached), 0x000F);
  EXPECT_TRUE(h.sink.done(7));
}

TEST(ProfilePosition, StaleTargetReachedFromThePreviousMoveDoesNotComplete) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 100)).accepted);
  for (int i = 0; i < 5; ++i) h.cycle(kSwEnabledReached);  // previous target still "reached", no ack yet
  EXPECT_FALSE(h.sink.done(7));
  h.cycle(kSwEnabledAck | 0x0400);  // ack (+ old bit 10)
  EXPECT_FALSE(h.sink.done(7));
  h.cycle(kSwEnabledReached);
  h.cycle(kSwEnabledReached);
  EXPECT_TRUE(h.sink.done(7));
}

TEST(ProfilePosition, RelativeAndImmediateBits) {
  Harness h;
  h.enable();
  auto c = move(7, -500);
  c.relative = true;
  c.immediate = true;
  ASSERT_TRUE(h.submit(c).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x007F);  // bit 4 + bit 5 immediate + bit 6 relative
}

// ESR/Dunker (quirk pp_bit6_absolute, dunker-ethercat-coe.md §14 item 14): bit 6 set is an
// absolute move there, so an absolute move sets it and a relative one clears it.
TEST(ProfilePosition, Bit6IsAbsoluteOnADriveWithThatQuirk) {
  MasterSettings s;
  s.pp_bit6_absolute = true;
  Harness h(s);
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 500)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x005F);  // bit 4 + bit 6 absolute
  h.cycle(kSwEnabledAck);
  h.cycle(kSwEnabledReached);
  h.cycle(kSwEnabledReached);
  h.cycle(kSwEnabledReached);
  ASSERT_TRUE(h.sink.done(7));
  auto c = move(8, -500);
  c.relative = true;
  ASSERT_TRUE(h.submit(c).accepted);
  EXPECT_EQ(h.cycle(kSwEnabledReached), 0x001F);  // bit 4, bit 6 clear: relative
}

TEST(ProfilePosition, AcyclicRampsMustAllBeDoneBeforeBit4Rises) {
  Harness h;
  h.io.unmap(obj::kProfileVelocity.id);  // e.g. default AKD RPDO2 without 6081h, and 6083h/6084h never mapped
  h.io.set_latency(3);
  h.enable();
  auto c = move(7, 10);
  c.profile_acceleration = 50;
  c.profile_deceleration = 50;
  ASSERT_TRUE(h.submit(c).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_EQ(h.io.acyclic_writes(), 3U);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);
  EXPECT_EQ(h.io.value(obj::kProfileAcceleration.id), 50);
}

TEST(ProfilePosition, RefusedWriteFailsTheMoveWithTheAbortText) {
  Harness h;
  h.io.abort_on(obj::kProfileAcceleration.id, 0x06090031);
  h.enable();
  auto c = move(7, 10);
  c.profile_acceleration = 99999999;
  ASSERT_TRUE(h.submit(c).accepted);
  for (int i = 0; i < 5; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.sink.failure(7),
            "drive refused 6083h:00 = 99999999: value of parameter written too high (download only) (abort code 0x06090031)");
  EXPECT_EQ(h.cw(), 0x000F);
}

TEST(ProfilePosition, NewerMoveSupersedesAndGetsAFreshEdge) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 100)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);
  ASSERT_TRUE(h.submit(move(8, 200)).accepted);
  EXPECT_EQ(h.sink.failure(7), "superseded by a newer move command");
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);  // bit 4 low for a cycle ...
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);  // ... then the new rising edge
  EXPECT_EQ(h.io.value(obj::kTargetPosition.id), 200);
}

TEST(ProfilePosition, WaitsForTheOldAcknowledgeToDrop) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 100)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabledAck), 0x000F);  // bit 12 still set: a new job would be ignored (NORD §5.1)
  EXPECT_EQ(h.cycle(kSwEnabledAck), 0x000F);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);
}

TEST(ProfilePosition, AcknowledgeTimeout) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 100)).accepted);
  for (int i = 0; i < 600; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.sink.failure(7), "drive did not acknowledge the new set-point (statusword bit 12) within 500 ms");
  EXPECT_EQ(h.cw(), 0x000F);
}

TEST(ProfilePosition, RejectedWhenNotEnabled) {
  Harness h;
  h.cycle(kSwSwitchOnDisabled);
  const auto a = h.submit(move(7, 100));
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "axis is not enabled: send enable first");
}

TEST(ModeSwitch, WritesModeAndWaitsForTheDisplay) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 100)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_EQ(h.io.value(obj::kModesOfOperation.id), op_mode::kProfilePosition);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);  // 6061h still 3: no set-point yet
  h.set_mode_display(op_mode::kProfilePosition);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);
  EXPECT_EQ(h.sink.count(core::EventKind::ModeChanged), 2U);  // pv seen first, then pp
}

TEST(ModeSwitch, ConfirmTimeoutSaysWhatTheDriveShows) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  ASSERT_TRUE(h.submit(command(7, CommandKind::SetMode, Mode::ProfilePosition)).accepted);
  for (int i = 0; i < 502; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.sink.failure(7), "drive did not confirm mode pp within 500 ms (6061h still shows 3 = pv)");
}

TEST(ModeSwitch, AcyclicModeWriteAndDisplayPoll) {
  Harness h;
  h.io.unmap(obj::kModesOfOperation.id);
  h.io.unmap(obj::kModesOfOperationDisplay.id);
  h.io.set(obj::kModesOfOperationDisplay.id, op_mode::kProfileVelocity);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwSwitchOnDisabled);
  EXPECT_EQ(h.master.feedback().mode, Mode::ProfileVelocity);
  ASSERT_TRUE(h.submit(command(7, CommandKind::SetMode, Mode::Homing)).accepted);
  for (int i = 0; i < 4; ++i) h.cycle(kSwSwitchOnDisabled);
  EXPECT_EQ(h.io.value(obj::kModesOfOperation.id), op_mode::kHoming);
  h.io.set(obj::kModesOfOperationDisplay.id, op_mode::kHoming);
  for (int i = 0; i < 4; ++i) h.cycle(kSwSwitchOnDisabled);
  EXPECT_TRUE(h.sink.done(7));
}

TEST(ModeSwitch, OnlyAtStandstill) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  h.io.set(obj::kVelocityActual.id, 1500);
  h.cycle(kSwEnabled);
  const auto a = h.submit(command(7, CommandKind::SetMode, Mode::ProfilePosition));
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "axis is moving: stop it before changing mode from pv to pp");
  h.io.set(obj::kVelocityActual.id, 0);
  EXPECT_TRUE(h.submit(command(8, CommandKind::SetMode, Mode::ProfilePosition)).accepted);
}

TEST(ProfileVelocity, WritesTargetAndCompletesOnVelocityReached) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  auto c = command(7, CommandKind::Velocity, Mode::ProfileVelocity);
  c.target_velocity = 16640;  // AKD digest §12.3 row 11
  ASSERT_TRUE(h.submit(c).accepted);
  EXPECT_EQ(h.cycle(kSwEnabledReached), 0x000F);  // pv has no mode bits
  EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 16640);
  h.cycle(kSwEnabledReached);  // stale bit 10 from velocity 0 within the settle cycles
  EXPECT_FALSE(h.sink.done(7));
  h.cycle(kSwEnabled);
  h.cycle(kSwEnabledReached);
  EXPECT_TRUE(h.sink.done(7));
}

TEST(ProfileVelocity, StopSetsVelocityZeroAndKeepsEnable) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  auto c = command(7, CommandKind::Velocity);
  c.target_velocity = 1000;
  ASSERT_TRUE(h.submit(c).accepted);
  h.cycle(kSwEnabled);
  ASSERT_TRUE(h.submit(command(8, CommandKind::Stop)).accepted);
  EXPECT_EQ(h.sink.failure(7), "aborted by a stop command");
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 0);
  for (int i = 0; i < 3; ++i) h.cycle(kSwEnabledReached);
  EXPECT_TRUE(h.sink.done(8));
}

TEST(VelocityVl, NordControlwordAndTarget) {
  Harness h;
  h.io.map(obj::kVlTargetVelocity.id);
  h.io.map(obj::kVlVelocityActual.id);
  h.set_mode_display(op_mode::kVelocity);
  h.enable();
  // No velocity command since the enable: the run bits stay low, whatever 6042h held before.
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  auto c = command(7, CommandKind::Velocity, Mode::Velocity);
  c.target_velocity = 1500;
  ASSERT_TRUE(h.submit(c).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x007F);  // NORD digest §5.2: 0x007F runs from the bus set-point
  EXPECT_EQ(h.io.value(obj::kVlTargetVelocity.id), 1500);
  for (int i = 0; i < 5; ++i) h.cycle(kSwEnabled);
  EXPECT_FALSE(h.sink.done(7));  // no bit 10 in vl: compares 6044h with 6042h
  h.io.set(obj::kVlVelocityActual.id, 1498);
  h.cycle(kSwEnabled);
  EXPECT_TRUE(h.sink.done(7));
  c.id = 8;
  c.target_velocity = 40000;
  EXPECT_FALSE(h.submit(c).accepted);  // 6042h is INTEGER16
}

TEST(ProfileTorque, TargetAndSlopeThenTorqueReached) {
  Harness h;
  h.io.set_latency(1);
  h.set_mode_display(op_mode::kProfileTorque);
  h.enable();
  auto c = command(7, CommandKind::Torque);
  c.target_torque = 400;  // AKD digest §12.4 row 11
  c.torque_slope = 2500;
  ASSERT_TRUE(h.submit(c).accepted);
  h.cycle(kSwEnabled);  // 6087h is not mapped: acyclic write in flight
  EXPECT_EQ(h.io.value(obj::kTargetTorque.id), 400);
  h.cycle(kSwEnabled);
  EXPECT_EQ(h.io.value(obj::kTorqueSlope.id), 2500);
  for (int i = 0; i < 3; ++i) h.cycle(kSwEnabled);
  EXPECT_FALSE(h.sink.done(7));
  h.cycle(kSwEnabledReached);
  EXPECT_TRUE(h.sink.done(7));
}

TEST(ProfileTorque, DrivesWithoutTorqueReachedCompleteOnceWritten) {
  MasterSettings s;
  s.torque_reached_bit = false;
  Harness h(s);
  h.set_mode_display(op_mode::kProfileTorque);
  h.enable();
  auto c = command(7, CommandKind::Torque);
  c.target_torque = 100;
  ASSERT_TRUE(h.submit(c).accepted);
  for (int i = 0; i < 3; ++i) h.cycle(kSwEnabled);
  EXPECT_TRUE(h.sink.done(7));
}

core::DriveCommand home(core::CommandId id, std::int8_t method) {
  auto c = command(id, CommandKind::Home);
  c.homing_method = method;
  c.homing_search_velocity = 10000;  // AKD digest §12.7 rows 4-10
  c.homing_zero_velocity = 5000;
  c.homing_acceleration = 10000;
  c.home_offset = 25000;
  return c;
}

TEST(Homing, AcyclicParametersThenBit4HeldUntilAttained) {
  Harness h;
  h.io.set_latency(1);
  h.set_mode_display(op_mode::kHoming);
  h.enable();
  ASSERT_TRUE(h.submit(home(7, 35)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);  // five acyclic writes in flight
  ASSERT_EQ(h.io.acyclic_writes(), 5U);
  EXPECT_EQ(h.io.acyclic_write(0).id, obj::kHomingMethod.id);
  EXPECT_EQ(h.io.acyclic_write(0).value, 35);
  EXPECT_EQ(h.io.acyclic_write(4).id, obj::kHomeOffset.id);
  EXPECT_EQ(h.io.acyclic_write(4).value, 25000);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);  // all Done: homing start
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);  // held (1 -> 0 would abort homing)
  EXPECT_EQ(h.cycle(kSwEnabledReached), 0x001F);
  EXPECT_FALSE(h.sink.done(7));
  EXPECT_EQ(h.cycle(kSwHomed), 0x000F);  // 0x1637: attained + target reached
  EXPECT_TRUE(h.sink.done(7));
  EXPECT_TRUE(h.master.feedback().homed);
}

TEST(Homing, StaleAttainedBitFromAnEarlierRunIsIgnored) {
  Harness h;
  h.set_mode_display(op_mode::kHoming);
  h.io.map(obj::kHomingMethod.id);
  h.io.map(obj::kHomeOffset.id);
  h.enable();
  auto c = command(7, CommandKind::Home);
  c.homing_method = 24;
  ASSERT_TRUE(h.submit(c).accepted);
  EXPECT_EQ(h.cycle(kSwHomed), 0x001F);
  EXPECT_FALSE(h.sink.done(7));
  EXPECT_EQ(h.cycle(kSwHomed), 0x001F);
  EXPECT_FALSE(h.sink.done(7));
  h.cycle(kSwEnabled);  // homing running
  h.cycle(kSwHomed);
  EXPECT_TRUE(h.sink.done(7));
}

TEST(Homing, ErrorBitFailsWithTheMethod) {
  Harness h;
  h.io.set_latency(1);
  h.set_mode_display(op_mode::kHoming);
  h.enable();
  ASSERT_TRUE(h.submit(home(7, 12)).accepted);
  h.cycle(kSwEnabled);
  h.cycle(kSwEnabled);
  for (int i = 0; i < 3; ++i) h.cycle(0x2237);  // bit 13 homing error
  EXPECT_EQ(h.sink.failure(7), "homing error (method 12)");
  EXPECT_EQ(h.cw(), 0x000F);
}

TEST(Homing, Timeout) {
  MasterSettings s;
  s.homing_timeout = 200ms;
  Harness h(s);
  h.io.set_latency(1);
  h.set_mode_display(op_mode::kHoming);
  h.enable();
  ASSERT_TRUE(h.submit(home(7, 17)).accepted);
  for (int i = 0; i < 250; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.sink.failure(7), "homing did not finish within 200 ms (method 17)");
  EXPECT_EQ(h.cw(), 0x000F);
}

TEST(CyclicPosition, HoldsActualPositionUntilTheFirstSetpoint) {
  Harness h;
  h.enable();
  h.io.set(obj::kPositionActual.id, 4242);
  ASSERT_TRUE(h.submit(command(7, CommandKind::SetMode, Mode::CyclicPosition)).accepted);
  h.cycle(kSwEnabled);
  h.set_mode_display(op_mode::kCyclicPosition);
  h.cycle(kSwEnabled);
  EXPECT_TRUE(h.sink.done(7));
  EXPECT_EQ(h.io.value(obj::kTargetPosition.id), 4242);
  h.io.set(obj::kPositionActual.id, 4300);  // drifts: the hold stays where the axis was
  h.cycle(kSwEnabled);
  EXPECT_EQ(h.io.value(obj::kTargetPosition.id), 4242);
  core::DriveSetpoint sp;
  sp.position = 5000;
  h.master.setpoint(sp, h.now);
  h.cycle(kSwEnabled);
  EXPECT_EQ(h.io.value(obj::kTargetPosition.id), 5000);
  // Stop: back to holding where the axis is now.
  ASSERT_TRUE(h.submit(command(8, CommandKind::Stop)).accepted);
  h.io.set(obj::kPositionActual.id, 4990);
  h.cycle(kSwEnabled);
  EXPECT_TRUE(h.sink.done(8));
  EXPECT_EQ(h.io.value(obj::kTargetPosition.id), 4990);
}

TEST(CyclicVelocity, HoldsZeroAndCountsUnmappedSetpoints) {
  Harness h;
  h.set_mode_display(op_mode::kCyclicVelocity);
  h.io.set(obj::kTargetVelocity.id, 777);
  h.enable();
  EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 0);
  h.io.unmap(obj::kTargetVelocity.id);
  core::DriveSetpoint sp;
  sp.velocity = 10;
  h.master.setpoint(sp, h.now);
  EXPECT_EQ(h.master.dropped_setpoints(), 1U);
}

TEST(InterpolatedPosition, Bit4EnablesInterpolationAndSetpointsGoTo60C1) {
  Harness h;
  h.io.map(obj::kIpDataRecord.id);
  h.set_mode_display(op_mode::kInterpolatedPosition);
  h.io.set(obj::kPositionActual.id, 10);
  h.enable();
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);  // AKD digest §8.3 step 5
  EXPECT_EQ(h.io.value(obj::kIpDataRecord.id), 10);
  core::DriveSetpoint sp;
  sp.position = 11;
  h.master.setpoint(sp, h.now);
  EXPECT_EQ(h.io.value(obj::kIpDataRecord.id), 11);
}

TEST(Halt, Bit8UntilStandstillThenResume) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  ASSERT_TRUE(h.submit(command(7, CommandKind::Halt)).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x010F);  // AKD digest §12.3 row 13
  EXPECT_TRUE(h.master.feedback().halted);
  for (int i = 0; i < 3; ++i) h.cycle(kSwEnabledReached);
  EXPECT_TRUE(h.sink.done(7));
  ASSERT_TRUE(h.submit(command(8, CommandKind::Resume)).accepted);
  EXPECT_TRUE(h.sink.done(8));
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
}

TEST(Halt, NewMoveImpliesResume) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(command(7, CommandKind::Halt)).accepted);
  h.cycle(kSwEnabled);
  ASSERT_TRUE(h.submit(move(8, 5)).accepted);
  EXPECT_EQ(h.sink.failure(7), "aborted by a move command");
  EXPECT_EQ(h.cycle(kSwEnabled), 0x001F);
}

TEST(Stop, ProfilePositionHaltsAndKeepsEnable) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(move(7, 1000)).accepted);
  h.cycle(kSwEnabled);
  h.cycle(kSwEnabledAck);
  ASSERT_TRUE(h.submit(command(8, CommandKind::Stop)).accepted);
  EXPECT_EQ(h.sink.failure(7), "aborted by a stop command");
  EXPECT_EQ(h.cycle(kSwEnabled), 0x010F);
  for (int i = 0; i < 3; ++i) h.cycle(kSwEnabledReached);
  EXPECT_TRUE(h.sink.done(8));
  EXPECT_EQ(h.master.feedback().state, core::AxisState::OperationEnabled);
}

}  // namespace
}  // namespace drivegate::cia402::test
