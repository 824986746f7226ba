// Safety rules of the master, cycle by cycle against the scripted drive: safe holds in the image,
// vl run bits, ip enable interpolation, cyclic mode prerequisites, cancelled requests, the stage
// timeout, fault reset and disable shortcuts, the standstill check and parameter ownership.
#include <gtest/gtest.h>

#include "profiles/cia402/controlword.hpp"
#include "tests/cia402/master_harness.hpp"
#include "tests/support/param_request.hpp"

namespace drivegate::cia402::test {
namespace {

using core::CommandKind;
using core::Mode;

core::ParamRequest write_param(core::CommandId id, std::uint16_t index, std::int64_t value) {
  return drivegate::test::param_write(id, index, 0, core::ParamType::I32, std::to_string(value));
}

// --- 1. Safe holds ---

TEST(SafeHolds, QuickStopDisableFaultAndLinkLossZeroTheTargets) {
  for (const auto kind : {CommandKind::QuickStop, CommandKind::Disable}) {
    Harness h;
    h.set_mode_display(op_mode::kProfileVelocity);
    h.enable();
    auto c = command(7, CommandKind::Velocity);
    c.target_velocity = 1000;
    ASSERT_TRUE(h.submit(c).accepted);
    h.cycle(kSwEnabled);
    ASSERT_EQ(h.io.value(obj::kTargetVelocity.id), 1000);
    h.io.set(obj::kTargetTorque.id, 55);
    ASSERT_TRUE(h.submit(command(8, kind)).accepted);
    EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 0) << core::to_string(kind);
    EXPECT_EQ(h.io.value(obj::kTargetTorque.id), 0) << core::to_string(kind);
  }
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  h.io.set(obj::kTargetVelocity.id, 1000);
  h.cycle(kSwFault);
  EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 0);
  h.io.set(obj::kTargetVelocity.id, 1000);
  h.master.link_lost(h.now, h.sink);
  EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 0);
}

TEST(SafeHolds, EnableWalkStartsWithZeroTargetsAndCspHoldsTheActualPosition) {
  Harness h;
  h.set_mode_display(op_mode::kCyclicPosition);
  h.io.set(obj::kTargetVelocity.id, 1000);
  h.io.set(obj::kTargetPosition.id, 99999);  // a stale csp set-point
  h.io.set(obj::kPositionActual.id, 1234);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 0);
  EXPECT_EQ(h.io.value(obj::kTargetPosition.id), 1234);
}

TEST(SafeHolds, EnableOnAnEnabledAxisKeepsItsMotion) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  auto c = command(7, CommandKind::Velocity);
  c.target_velocity = 1000;
  ASSERT_TRUE(h.submit(c).accepted);
  h.cycle(kSwEnabled);
  ASSERT_TRUE(h.submit(command(8, CommandKind::Enable)).accepted);  // no walk: nothing to reset
  h.cycle(kSwEnabled);
  EXPECT_TRUE(h.sink.done(8));
  EXPECT_EQ(h.io.value(obj::kTargetVelocity.id), 1000);
}

TEST(SafeHolds, VlRunBitsNeedAVelocityCommandSinceTheLastEnable) {
  Harness h;
  h.io.map(obj::kVlTargetVelocity.id);
  h.io.map(obj::kVlVelocityActual.id);
  h.set_mode_display(op_mode::kVelocity);
  h.enable();
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  auto c = command(7, CommandKind::Velocity, Mode::Velocity);
  c.target_velocity = 1500;
  ASSERT_TRUE(h.submit(c).accepted);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x007F);
  ASSERT_TRUE(h.submit(command(8, CommandKind::QuickStop)).accepted);
  EXPECT_EQ(h.io.value(obj::kVlTargetVelocity.id), 0);
  h.cycle(kSwQuickStop);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(9, CommandKind::Enable)).accepted);
  h.cycle(kSwSwitchOnDisabled);
  h.cycle(kSwReady);
  h.cycle(kSwSwitchedOn);
  h.cycle(kSwEnabled);
  EXPECT_TRUE(h.sink.done(9));
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);  // a bare enable does not run the ramp generator
}

// --- 2. ip and the cyclic modes' prerequisites ---

TEST(CyclicPrerequisites, ModesNeedTheirTargetInTheImage) {
  Harness h;  // maps 607Ah, 60FFh, 6071h, 6064h but not 60C1h:1
  h.cycle(kSwSwitchOnDisabled);
  auto a = h.submit(command(7, CommandKind::SetMode, Mode::InterpolatedPosition));
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "interpolated position needs 60C1h:1 in the cyclic image");
  EXPECT_TRUE(h.submit(command(8, CommandKind::SetMode, Mode::CyclicPosition)).accepted);
  h.io.unmap(obj::kTargetPosition.id);
  h.io.unmap(obj::kTargetVelocity.id);
  h.io.unmap(obj::kTargetTorque.id);
  a = h.submit(command(9, CommandKind::SetMode, Mode::CyclicPosition));
  EXPECT_EQ(a.reason.view(), "cyclic synchronous position needs 607Ah in the cyclic image");
  a = h.submit(command(10, CommandKind::SetMode, Mode::CyclicVelocity));
  EXPECT_EQ(a.reason.view(), "cyclic synchronous velocity needs 60FFh in the cyclic image");
  a = h.submit(command(11, CommandKind::SetMode, Mode::CyclicTorque));
  EXPECT_EQ(a.reason.view(), "cyclic synchronous torque needs 6071h in the cyclic image");
  h.io.map(obj::kIpDataRecord.id);
  h.io.unmap(obj::kPositionActual.id);
  a = h.submit(command(12, CommandKind::SetMode, Mode::InterpolatedPosition));
  EXPECT_EQ(a.reason.view(), "interpolated position needs 6064h in the cyclic image");
}

TEST(CyclicPrerequisites, IpBit4OnlyWithTheHoldIn60C1) {
  Harness h;
  h.io.map(obj::kIpDataRecord.id);
  h.io.unmap(obj::kPositionActual.id);  // where the axis stands is unknown
  h.io.set(obj::kIpDataRecord.id, 777);
  h.set_mode_display(op_mode::kInterpolatedPosition);
  h.enable();
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
  EXPECT_EQ(h.cycle(kSwEnabled), 0x000F);
}

// --- 3. Cancelled requests and the stage timeout ---

core::DriveCommand acyclic_move(core::CommandId id, std::int32_t target) {
  auto c = command(id, CommandKind::Move);
  c.target_position = target;
  c.profile_velocity = 100;
  c.profile_acceleration = 50;
  c.profile_deceleration = 50;
  return c;
}

TEST(Requests, SupersededMoveCancelsItsStagedWrites) {
  Harness h;
  h.io.unmap(obj::kProfileVelocity.id);
  h.io.set_latency(10);
  h.enable();
  ASSERT_TRUE(h.submit(acyclic_move(7, 10)).accepted);
  h.cycle(kSwEnabled);
  ASSERT_EQ(h.io.pending_requests(), 3U);
  ASSERT_TRUE(h.submit(acyclic_move(8, 20)).accepted);
  EXPECT_EQ(h.io.cancels(), 3U);
  EXPECT_EQ(h.io.pending_requests(), 0U);
  h.cycle(kSwEnabled);
  EXPECT_EQ(h.io.pending_requests(), 3U);  // only the new move's
}

TEST(Requests, FailedWriteCancelsTheRestOfTheBatch) {
  Harness h;
  h.io.unmap(obj::kProfileVelocity.id);
  h.io.abort_on(obj::kProfileVelocity.id, 0x06090031);
  h.io.set_latency(1);
  h.enable();
  ASSERT_TRUE(h.submit(acyclic_move(7, 10)).accepted);
  h.cycle(kSwEnabled);  // three writes submitted
  h.cycle(kSwEnabled);  // the first fails
  EXPECT_FALSE(h.sink.failure(7).empty());
  EXPECT_EQ(h.io.pending_requests(), 0U);
}

TEST(Requests, LinkLossCancelsEverythingInFlight) {
  Harness h;
  h.io.unmap(obj::kStatusword.id);
  h.io.unmap(obj::kControlword.id);
  h.io.unmap(obj::kErrorCode.id);
  h.io.set_latency(50);
  h.io.set(obj::kStatusword.id, kSwFault);
  core::ParamRequest rq;
  rq.id = 9;
  rq.index = 0x1000;
  ASSERT_TRUE(h.master.parameter(rq, h.now).accepted);
  for (int i = 0; i < 60; ++i) h.master.update(h.now, h.sink);  // status read done: fault, 603Fh read
  ASSERT_GT(h.io.pending_requests(), 0U);
  h.master.link_lost(h.now, h.sink);
  EXPECT_EQ(h.io.pending_requests(), 0U);
}

TEST(Requests, StageTimeoutFailsTheCommandNamingTheObject) {
  Harness h;
  h.io.unmap(obj::kProfileVelocity.id);
  h.enable();
  h.io.set_queue_full(true);
  ASSERT_TRUE(h.submit(acyclic_move(7, 10)).accepted);
  for (int i = 0; i < 1002; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.sink.failure(7),
            "drive did not take 6081h:00 = 100 within 1000 ms: SDO protocol timed out (no answer, or no free request slot)");
  EXPECT_EQ(h.cw(), 0x000F);
}

// --- 4./5. Fault reset and disable ---

TEST(DeviceCommands, FaultResetWhileEnablingLeavesTheWalkAlone) {
  Harness h;
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(2, CommandKind::FaultReset)).accepted);
  EXPECT_TRUE(h.sink.done(2));
  EXPECT_EQ(h.cycle(kSwReady), 0x0007);
  h.cycle(kSwSwitchedOn);
  h.cycle(kSwEnabled);
  EXPECT_TRUE(h.sink.done(1));
  EXPECT_TRUE(h.sink.failure(1).empty()) << h.sink.failure(1);
}

TEST(DeviceCommands, DisableInFaultOrNotReadyCompletesAtOnce) {
  Harness h;
  h.cycle(kSwFault);
  ASSERT_TRUE(h.submit(command(1, CommandKind::FaultReset)).accepted);
  EXPECT_EQ(h.cycle(kSwFault), 0x0080);
  ASSERT_TRUE(h.submit(command(2, CommandKind::Disable)).accepted);
  EXPECT_TRUE(h.sink.done(2));
  EXPECT_EQ(h.sink.failure(1), "aborted by a disable command");
  EXPECT_EQ(h.cycle(kSwFault), 0x0000);
  Harness n;
  n.cycle(0x0000);  // not ready to switch on
  ASSERT_TRUE(n.submit(command(3, CommandKind::Disable)).accepted);
  EXPECT_TRUE(n.sink.done(3));
}

TEST(DeviceCommands, FaultDuringADisableWalkCompletesIt) {
  Harness h;
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::Disable)).accepted);
  h.cycle(kSwEnabled);
  h.cycle(kSwFault);
  EXPECT_TRUE(h.sink.done(2));
}

// --- 6. Standstill before a mode change ---

TEST(Standstill, VelocityReachedInPvIsNotStandstill) {
  Harness h;
  h.io.unmap(obj::kVelocityActual.id);
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  auto c = command(7, CommandKind::Velocity);
  c.target_velocity = 1000;
  ASSERT_TRUE(h.submit(c).accepted);
  for (int i = 0; i < 5; ++i) h.cycle(kSwEnabledReached);  // running at 1000: "velocity reached"
  auto a = h.submit(command(8, CommandKind::SetMode, Mode::ProfilePosition));
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "axis is moving: stop it before changing mode from pv to pp");
  ASSERT_TRUE(h.submit(command(9, CommandKind::Stop)).accepted);
  h.cycle(kSwEnabled);
  EXPECT_FALSE(h.submit(command(10, CommandKind::SetMode, Mode::ProfilePosition)).accepted);  // ramping down
  for (int i = 0; i < 3; ++i) h.cycle(kSwEnabledReached);  // velocity 0 reached
  EXPECT_TRUE(h.submit(command(11, CommandKind::SetMode, Mode::ProfilePosition)).accepted);
}

TEST(Standstill, TorqueModeNeedsHaltWithoutVelocityActual) {
  Harness h;
  h.io.unmap(obj::kVelocityActual.id);
  h.set_mode_display(op_mode::kProfileTorque);
  h.enable();
  h.cycle(kSwEnabledReached);  // "torque reached" says nothing about the speed
  EXPECT_FALSE(h.submit(command(7, CommandKind::SetMode, Mode::ProfilePosition)).accepted);
  ASSERT_TRUE(h.submit(command(8, CommandKind::Halt)).accepted);
  for (int i = 0; i < 3; ++i) h.cycle(kSwEnabledReached);
  EXPECT_TRUE(h.submit(command(9, CommandKind::SetMode, Mode::ProfilePosition)).accepted);
}

TEST(Standstill, VelocityActualWithinASmallWindow) {
  Harness h;
  h.set_mode_display(op_mode::kProfileVelocity);
  h.enable();
  h.io.set(obj::kVelocityActual.id, -4);  // encoder jitter at rest
  h.cycle(kSwEnabled);
  EXPECT_TRUE(h.submit(command(7, CommandKind::SetMode, Mode::ProfilePosition)).accepted);
  EXPECT_GT(MasterSettings{}.standstill_velocity, 0);
}

// --- 7. Parameter writes do not bypass the profile ---

TEST(ParameterOwnership, ProfileObjectsAreReadOnlyForClients) {
  Harness h;  // 607Ah is mapped, 6081h unmapped here
  h.io.unmap(obj::kProfileVelocity.id);
  h.io.unmap(obj::kTargetVelocity.id);
  h.enable();
  auto a = h.master.parameter(write_param(1, 0x6040, 15), h.now);
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason.view(), "6040h is driven by the CiA 402 profile; use the axis commands");
  EXPECT_FALSE(h.master.parameter(write_param(2, 0x60FF, 100), h.now).accepted);  // unmapped target
  EXPECT_FALSE(h.master.parameter(write_param(3, 0x6060, 3), h.now).accepted);
  EXPECT_FALSE(h.master.parameter(write_param(4, 0x6064, 0), h.now).accepted);  // in the image
  EXPECT_TRUE(h.master.parameter(write_param(5, 0x6081, 100), h.now).accepted);  // no motion in flight
  ASSERT_TRUE(h.submit(acyclic_move(6, 10)).accepted);
  a = h.master.parameter(write_param(7, 0x6081, 100), h.now);
  EXPECT_EQ(a.reason.view(), "6081h is driven by the CiA 402 profile; use the axis commands");
  EXPECT_FALSE(h.master.parameter(write_param(8, 0x605A, 1), h.now).accepted);
  auto read = write_param(9, 0x6040, 0);
  read.write = false;
  EXPECT_TRUE(h.master.parameter(read, h.now).accepted);  // reads stay allowed
}

}  // namespace
}  // namespace drivegate::cia402::test

namespace drivegate::cia402::test {
namespace {

// The drive stays enabled although the gateway sends quick stop (its RPDO was switched off behind
// the gateway's back): after the follow timeout that is a lost control, reported once to the bus
// adapter and as an event.
TEST(ControlSupervision, ADriveThatDoesNotLeaveOperationEnabledIsControlLost) {
  MasterSettings s;
  s.follow_timeout = std::chrono::milliseconds(100);
  Harness h(s);
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::QuickStop)).accepted);
  for (int i = 0; i < 100; ++i) h.cycle(kSwEnabled);  // 100 ms: still within the timeout
  EXPECT_EQ(h.io.control_losses(), 0);
  for (int i = 0; i < 5; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.io.control_losses(), 1);
  bool event = false;
  for (const auto& e : h.sink.events)
    if (e.kind == core::EventKind::ControlLost) {
      event = true;
      EXPECT_NE(e.text.find("does not follow its controlword: still operation_enabled"), std::string::npos) << e.text;
    }
  EXPECT_TRUE(event);
  for (int i = 0; i < 500; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.io.control_losses(), 1);  // once per loss
  // After the link went and came back the supervision starts afresh.
  h.master.link_lost(h.now, h.sink);
  h.enable();
  ASSERT_TRUE(h.submit(command(3, CommandKind::Disable)).accepted);
  for (int i = 0; i < 150; ++i) h.cycle(kSwEnabled);
  EXPECT_EQ(h.io.control_losses(), 2);
}

// A drive that follows in time, or one that refuses to enable (no DC bus), keeps control.
TEST(ControlSupervision, FollowingOrRefusingToEnableIsNotControlLost) {
  MasterSettings s;
  s.follow_timeout = std::chrono::milliseconds(100);
  Harness h(s);
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::QuickStop)).accepted);
  for (int i = 0; i < 50; ++i) h.cycle(kSwEnabled);
  for (int i = 0; i < 500; ++i) h.cycle(kSwQuickStop);
  for (int i = 0; i < 50; ++i) h.cycle(kSwSwitchOnDisabled);
  ASSERT_TRUE(h.submit(command(3, CommandKind::Enable)).accepted);
  for (int i = 0; i < 1000; ++i) h.cycle(kSwReady);  // stays in ready to switch on: a refusal
  EXPECT_EQ(h.io.control_losses(), 0);
  // Stale inputs say nothing about the drive: no verdict on them.
  Harness stale(s);
  stale.enable();
  ASSERT_TRUE(stale.submit(command(2, CommandKind::Disable)).accepted);
  stale.io.set_fresh(false);
  for (int i = 0; i < 500; ++i) stale.cycle(kSwEnabled);
  EXPECT_EQ(stale.io.control_losses(), 0);
}

// Objects the bus configured are not writable through parameters; reading them is.
TEST(ControlSupervision, WritesToObjectsTheBusOwnsAreRefusedWithTheOwner) {
  Harness h;
  h.io.own(0x1400);
  h.cycle(kSwSwitchOnDisabled);
  core::ParamRequest w = drivegate::test::param_write(9, 0x1400, 1, core::ParamType::U32, "0x80000201");
  const auto r = h.master.parameter(w, h.now);
  ASSERT_FALSE(r.accepted);
  EXPECT_NE(std::string(r.reason.view()).find("1400h:01 is owned by the test bus"), std::string::npos)
      << r.reason.view();
  EXPECT_NE(std::string(r.reason.view()).find("out of the gateway's control"), std::string::npos) << r.reason.view();
  w.write = false;
  EXPECT_TRUE(h.master.parameter(w, h.now).accepted);
}

}  // namespace
}  // namespace drivegate::cia402::test
