// Device control: every CiA 402 transition 0-16 driven by raw controlwords [AKD digest §3.2, §1].
#include <gtest/gtest.h>

#include "tests/cia402_sim/drive_harness.hpp"

namespace drivegate::cia402::sim::test {
namespace {

bool is_not_ready(std::uint16_t sw) { return sw_is(sw, 0x4F, 0x00); }
bool is_switch_on_disabled(std::uint16_t sw) { return sw_is(sw, 0x4F, 0x40); }
bool is_ready(std::uint16_t sw) { return sw_is(sw, 0x6F, 0x21); }
bool is_switched_on(std::uint16_t sw) { return sw_is(sw, 0x6F, 0x23); }
bool is_enabled(std::uint16_t sw) { return sw_is(sw, 0x6F, 0x27); }
bool is_quick_stop(std::uint16_t sw) { return sw_is(sw, 0x6F, 0x07); }
bool is_fault_reaction(std::uint16_t sw) { return sw_is(sw, 0x4F, 0x0F); }
bool is_fault(std::uint16_t sw) { return sw_is(sw, 0x4F, 0x08); }

TEST(StateMachine, PowerUpTransitions0And1) {
  DriveHarness h;
  EXPECT_TRUE(is_not_ready(h.sw()));  // 0
  h.step();
  EXPECT_TRUE(is_switch_on_disabled(h.sw()));  // 1
  EXPECT_EQ(h.sw(), 0x0240);  // the AKD's power-up statusword
  EXPECT_EQ(h.get(obj::kModesOfOperationDisplay), 0);
}

TEST(StateMachine, EnableSequence2To4WithManualStatuswords) {
  DriveHarness h;
  h.step();
  h.cw(0x0006);
  h.step();
  EXPECT_TRUE(is_ready(h.sw()));  // 2
  EXPECT_EQ(h.sw(), 0x0231);
  h.cw(0x0007);
  h.step();
  EXPECT_TRUE(is_switched_on(h.sw()));  // 3
  EXPECT_EQ(h.sw(), 0x0233);
  h.cw(0x000F);
  h.step();
  EXPECT_TRUE(is_enabled(h.sw()));  // 4
  EXPECT_EQ(h.sw() & 0x03FF, 0x0237);
}

TEST(StateMachine, NoStateIsSkippedAndOneChangePerStep) {
  DriveHarness h;
  h.step();
  h.cw(0x000F);  // enable operation from Switch on disabled: not a legal command there
  h.step(5);
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);
  h.cw(0x0006);
  h.step();
  ASSERT_EQ(h.state(), DriveState::ReadyToSwitchOn);
  h.cw(0x000F);  // allowed from Ready to switch on, but through Switched on [AKD digest §3.2]
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchedOn);
  h.step();
  EXPECT_EQ(h.state(), DriveState::OperationEnabled);
}

TEST(StateMachine, Transition5DisableOperationRampsThenHolds) {
  DriveHarness h;
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kTargetVelocity, 100000);
  h.step(200);
  ASSERT_NEAR(h.drive.velocity(), 100000.0, 1000.0);
  h.cw(0x0007);
  h.step();
  EXPECT_EQ(h.state(), DriveState::OperationEnabled);  // decelerating on 6084h first (605Ch = 1)
  EXPECT_GT(h.run_until([&] { return h.state() == DriveState::SwitchedOn; }), 80);
  EXPECT_LT(std::abs(h.drive.velocity()), 100.0);  // standstill: below 0.01 rev/s
  const double held = h.drive.position();
  h.step(100);
  EXPECT_NEAR(h.drive.position(), held, 5.0);  // Switched on holds the position (AKD quirk 1)
}

TEST(StateMachine, Transition6And7And10) {
  DriveHarness h;
  h.enable(op_mode::kProfilePosition);
  h.cw(0x0007);
  h.step(2);
  ASSERT_EQ(h.state(), DriveState::SwitchedOn);
  h.cw(0x0006);
  h.step();
  EXPECT_EQ(h.state(), DriveState::ReadyToSwitchOn);  // 6
  h.cw(0x0002);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);  // 7 by quick stop
  h.cw(0x0006);
  h.step();
  h.cw(0x0000);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);  // 7 by disable voltage
  h.cw(0x0006);
  h.step();
  h.cw(0x0007);
  h.step();
  ASSERT_EQ(h.state(), DriveState::SwitchedOn);
  h.cw(0x0000);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);  // 10 by disable voltage
  h.cw(0x0006);
  h.step();
  h.cw(0x0007);
  h.step();
  h.cw(0x0002);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);  // 10 by quick stop
}

TEST(StateMachine, Transition8And9RemoveTorque) {
  DriveHarness h;
  h.enable(op_mode::kProfilePosition);
  h.cw(0x0006);
  h.step();
  EXPECT_EQ(h.state(), DriveState::ReadyToSwitchOn);  // 8 (605Bh = 0: at once)
  EXPECT_EQ(h.drive.torque(), 0.0);
  h.cw(0x0007);
  h.step();
  h.cw(0x000F);
  h.step();
  ASSERT_EQ(h.state(), DriveState::OperationEnabled);
  h.cw(0x0000);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);  // 9
}

TEST(StateMachine, Transition11And12QuickStopOption2) {
  DriveHarness h;
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kTargetVelocity, 100000);
  h.step(200);
  h.cw(0x000B);  // bit 2 cleared
  h.step();
  EXPECT_TRUE(is_quick_stop(h.sw()));  // 11
  // Quick stop ramp 6085h = 1e7 units/s^2: the demand stops within 10 ms, the motor settles behind
  // it, then Switch on disabled.
  const int steps = h.run_until([&] { return h.state() == DriveState::SwitchOnDisabled; });
  EXPECT_GE(steps, 8);
  EXPECT_LE(steps, 50);
  EXPECT_EQ(h.get(obj::kTargetVelocity), 100000);
}

TEST(StateMachine, QuickStopOption1UsesTheSlowRamp) {
  DriveHarness h;
  h.set(obj::kQuickStopOption, 1);
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kTargetVelocity, 100000);
  h.step(200);
  h.cw(0x0002);
  h.step();
  ASSERT_EQ(h.state(), DriveState::QuickStopActive);
  const int steps = h.run_until([&] { return h.state() == DriveState::SwitchOnDisabled; });
  EXPECT_GE(steps, 95);  // 6084h = 1e6 units/s^2: 100 ms plus settling
  EXPECT_LE(steps, 150);
}

TEST(StateMachine, QuickStopOptions5And6StayAndTransition16) {
  for (const std::int64_t option : {5, 6}) {
    DriveHarness h;
    h.set(obj::kQuickStopOption, option);
    h.enable(op_mode::kProfileVelocity);
    h.set(obj::kTargetVelocity, 50000);
    h.step(200);
    h.cw(0x000B);
    h.step(300);
    EXPECT_EQ(h.state(), DriveState::QuickStopActive) << option;
    EXPECT_LT(std::abs(h.drive.velocity()), 100.0);
    EXPECT_NE(h.sw() & 0x0400, 0) << "target reached once stopped";
    h.cw(0x000F);
    h.step();
    EXPECT_EQ(h.state(), DriveState::OperationEnabled) << option;  // 16
  }
}

TEST(StateMachine, QuickStopOptionValuesAreChecked) {
  DriveHarness h;
  for (const std::int64_t bad : {0, 3, 4, 7, 8, -1}) {
    EXPECT_EQ(h.drive.write_object(obj::kQuickStopOption.id, bad), 0x06090030U) << bad;
  }
  EXPECT_EQ(h.get(obj::kQuickStopOption), 2);  // default [AKD digest §3.5]
}

TEST(StateMachine, Transition12DisableVoltageFromQuickStop) {
  DriveHarness h;
  h.set(obj::kQuickStopOption, 6);
  h.enable(op_mode::kProfilePosition);
  h.cw(0x0002);
  h.step(3);
  ASSERT_EQ(h.state(), DriveState::QuickStopActive);
  h.cw(0x0000);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);
}

TEST(StateMachine, FaultInjectionTransitions13To15WithEdgeOnlyReset) {
  DriveHarness h;
  h.enable(op_mode::kProfileVelocity);
  h.set(obj::kTargetVelocity, 100000);
  h.step(200);
  h.drive.inject_fault(0x2310);  // over-current class
  h.step();
  EXPECT_TRUE(is_fault_reaction(h.sw()));  // 13
  EXPECT_EQ(h.get(obj::kErrorCode), 0x2310);
  EXPECT_EQ(h.get(obj::kErrorRegister), 0x03);  // generic + current
  const auto emcy = h.drive.take_pending_emcy();
  ASSERT_TRUE(emcy.has_value());
  EXPECT_EQ(emcy->error_code, 0x2310);
  EXPECT_EQ(emcy->error_register, 0x03);
  EXPECT_FALSE(h.drive.take_pending_emcy().has_value());
  // The fault reaction brakes on the quick stop ramp (605Eh = 2), then Fault.
  EXPECT_GT(h.run_until([&] { return is_fault(h.sw()); }), 5);  // 14
  EXPECT_EQ(h.drive.torque(), 0.0);

  h.cw(0x0080);  // reset while the cause persists: refused
  h.step(3);
  EXPECT_EQ(h.state(), DriveState::Fault);
  h.drive.clear_fault_cause();
  h.step(3);  // bit 7 still high: no edge, no reset
  EXPECT_EQ(h.state(), DriveState::Fault);
  h.cw(0x0000);
  h.step();
  h.cw(0x0080);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);  // 15
  EXPECT_EQ(h.get(obj::kErrorCode), 0);
  EXPECT_EQ(h.get(obj::kErrorRegister), 0);
  const auto cleared = h.drive.take_pending_emcy();
  ASSERT_TRUE(cleared.has_value());
  EXPECT_EQ(cleared->error_code, 0);
  // The master must clear bit 7 and walk the sequence again.
  h.cw(0x0086);
  h.step();
  EXPECT_EQ(h.state(), DriveState::ReadyToSwitchOn);
}

TEST(StateMachine, FaultFromSwitchOnDisabledGoesStraightThrough) {
  DriveHarness h;
  h.step();
  h.drive.inject_fault(0x4210);
  h.step();
  EXPECT_EQ(h.state(), DriveState::FaultReactionActive);
  h.step();
  EXPECT_EQ(h.state(), DriveState::Fault);
  EXPECT_EQ(h.get(obj::kErrorRegister), 0x09);  // generic + temperature
}

TEST(StateMachine, HardwareEnableLossDropsWithoutFault) {
  DriveHarness h;
  h.enable(op_mode::kProfilePosition);
  h.drive.set_hardware_enable(false);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);
  EXPECT_EQ(h.sw() & 0x0008, 0);
  h.cw(0x0006);
  h.step(3);
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);  // cannot leave without the enable input
  h.drive.set_hardware_enable(true);
  h.step();
  EXPECT_EQ(h.state(), DriveState::ReadyToSwitchOn);
}

TEST(StateMachine, WarningAndRemoteBits) {
  DriveHarness h;
  h.step();
  EXPECT_NE(h.sw() & 0x0200, 0);
  h.drive.set_warning(true);
  h.step();
  EXPECT_NE(h.sw() & 0x0080, 0);
  h.drive.set_warning(false);
  h.step();
  EXPECT_EQ(h.sw() & 0x0080, 0);
}

TEST(StateMachine, PowerCycleResetsDictionaryAndKeepsOrResetsPosition) {
  for (const bool keep : {true, false}) {
    DriveModelConfig cfg;
    cfg.keep_position_on_power_cycle = keep;
    DriveHarness h(cfg);
    h.enable(op_mode::kProfileVelocity);
    h.set(obj::kProfileAcceleration, 2000000);
    h.set(obj::kTargetVelocity, 50000);
    h.step(300);
    const double before = h.drive.position();
    ASSERT_GT(before, 5000.0);
    h.drive.power_cycle();
    EXPECT_EQ(h.state(), DriveState::NotReadyToSwitchOn);
    EXPECT_EQ(h.get(obj::kProfileAcceleration), 1000000);  // back to default
    EXPECT_EQ(h.get(obj::kControlword), 0);
    h.step();
    EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);
    if (keep) {
      EXPECT_NEAR(static_cast<double>(h.get(obj::kPositionActual)), before, 1.0);
    } else {
      EXPECT_EQ(h.get(obj::kPositionActual), 0);
    }
  }
}

TEST(StateMachine, PersistentFaultSurvivesPowerCycle) {
  DriveHarness h;
  h.step();
  h.drive.inject_fault(0x3210);
  h.step(3);
  ASSERT_EQ(h.state(), DriveState::Fault);
  h.drive.power_cycle();
  h.step(4);
  EXPECT_EQ(h.state(), DriveState::Fault);
  EXPECT_EQ(h.get(obj::kErrorCode), 0x3210);
  h.drive.clear_fault_cause();
  h.cw(0x0080);
  h.step();
  EXPECT_EQ(h.state(), DriveState::SwitchOnDisabled);
}

TEST(StateMachine, EmcyQueueOverflowIsCounted) {
  DriveHarness h;
  h.step();
  for (int i = 0; i < 6; ++i) {
    h.drive.inject_fault(static_cast<std::uint16_t>(0xFF00 + i));
    h.step(3);
    h.drive.clear_fault_cause();
    h.cw(0x0000);
    h.step();
    h.cw(0x0080);
    h.step();
  }
  EXPECT_EQ(h.drive.emcy_overflows(), 4U);  // 12 events into 8 places
  int n = 0;
  while (h.drive.take_pending_emcy()) ++n;
  EXPECT_EQ(n, 8);
}

}  // namespace
}  // namespace drivegate::cia402::sim::test
