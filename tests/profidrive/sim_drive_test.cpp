// The simulated AKD PROFIdrive drive, cyclic side: state machine with the AKD's rules, speed mode,
// position mode (homing, MDI, program mode), jog, faults, invalid outputs, free telegrams and no
// allocation [akd-profinet-profidrive.md §7-§9, §14-§18, §20, §25].
#include <gtest/gtest.h>

#include <cmath>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/scaling.hpp"
#include "profiles/profidrive/state_machine.hpp"
#include "tests/profidrive/sim_harness.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profidrive::sim::test {
namespace {

constexpr std::uint16_t kRun = stw1_word::kSpeedRun;        // 0x047F
constexpr std::uint16_t kTaskReady = stw1_word::kTaskReady;  // 0x043F
constexpr std::uint16_t kTaskGo = stw1_word::kTaskActivate;  // 0x047F
constexpr std::uint16_t kHoming = stw1_word::kHoming;        // 0x0C0F

bool bit(std::uint16_t w, std::uint16_t b) { return (w & b) != 0; }

// --- State machine -------------------------------------------------------------------------------

TEST(ProfidriveSimStateMachine, EnableSequenceOfTheManualReachesS4) {
  // §15.1: 0x0470 (S1), 0x0476 (S2), 0x0477 (S3), 0x047F (S4); the ZSW1 patterns of §9.4, and the
  // controller-side decoder reads the same states from them.
  Harness h(config_for(1));
  struct Step {
    std::uint16_t stw1;
    State state;
    std::uint16_t zsw1;
    core::AxisState decoded;
  };
  for (const Step s : {Step{0x0470, State::S1SwitchingOnInhibited, 0x0240, core::AxisState::SwitchOnDisabled},
                       Step{0x0476, State::S2ReadyForSwitchingOn, 0x0231, core::AxisState::ReadyToSwitchOn},
                       Step{0x0477, State::S3SwitchedOn, 0x0233, core::AxisState::SwitchedOn},
                       Step{0x047F, State::S4Operation, 0x0737, core::AxisState::OperationEnabled}}) {
    h.send(s.stw1);
    EXPECT_EQ(h.drive.state(), s.state) << std::hex << s.stw1;
    EXPECT_EQ(h.act.zsw1, s.zsw1) << std::hex << s.stw1;
    EXPECT_EQ(decode_state(h.act.zsw1, s.stw1).state, s.decoded) << std::hex << s.stw1;
  }
}

TEST(ProfidriveSimStateMachine, S7ExampleRunningFramesByteExact) {
  // §20.3: controller -> AKD 04 7F 00 A3, AKD -> controller 02 37 00 9E. The example's drive ran 3 %
  // below its setpoint (158 for 163) with bits 8 and 10 low; the droop reproduces that load.
  DriveModelConfig c = config_for(1);
  c.speed_droop = 0.03;
  Harness h(c);
  h.enable(stw1::kSpeedRunBits);
  const std::array<std::uint8_t, 4> frame{0x04, 0x7F, 0x00, 0xA3};
  std::array<std::uint8_t, 4> actual{};
  for (int i = 0; i < 500; ++i) h.drive.step(1ms, frame, actual);
  EXPECT_EQ(actual, (std::array<std::uint8_t, 4>{0x02, 0x37, 0x00, 0x9E}));
}

TEST(ProfidriveSimStateMachine, PrintedS7SequenceWaitsInS2OnItsThirdWord) {
  // §20.2 prints 0x0400, 0x0406, 0x040E, 0x040F: 0x040E lacks ON, so the drive stays in S2 [§23.5];
  // 0x040F then takes it to S3 and, one transition per cycle, to S4.
  Harness h(config_for(1));
  h.send(0x0400);
  h.send(0x0406);
  h.send(0x040E);
  h.cycles(3);
  EXPECT_EQ(h.drive.state(), State::S2ReadyForSwitchingOn);
  h.send(0x040F);
  EXPECT_EQ(h.drive.state(), State::S3SwitchedOn);
  h.cycle();
  EXPECT_EQ(h.drive.state(), State::S4Operation);
}

TEST(ProfidriveSimStateMachine, WithoutControlByPlcTheTelegramIsIgnored) {
  // §8.1, §25.18: bit 10 low and the AKD ignores the controller: no state change, setpoints kept.
  Harness h(config_for(1));
  h.send(0x0006);
  h.send(0x0007);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
  EXPECT_EQ(h.drive.counters().not_controlled_by_plc, 2U);
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;  // 3000 rpm
  h.cycles(200);
  h.sp.stw1 = kRun & ~stw1::kControlByPlc & ~stw1::kOn;  // OFF1 without bit 10: not taken
  h.sp.nsoll_a = 0;
  h.cycles(50);
  EXPECT_EQ(h.drive.state(), State::S4Operation);
  EXPECT_NEAR(h.drive.velocity_rps(), 50.0, 0.5);
}

TEST(ProfidriveSimStateMachine, Off1RampsThroughS5ToS2) {
  Harness h(config_for(1));
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;
  h.cycles(200);
  h.send(0x0476);  // ON low
  EXPECT_EQ(h.drive.state(), State::S5RampStop);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kOperationEnabled));  // bit 2 drops while stopping [§7]
  EXPECT_EQ(decode_state(h.act.zsw1, 0x0476), (DriveState{core::AxisState::ReadyToSwitchOn, true}));
  EXPECT_GT(h.drive.velocity_rps(), 40.0);  // a ramp, not a coast or a jump
  ASSERT_TRUE(h.until([&] { return h.drive.state() == State::S2ReadyForSwitchingOn; }, 200));
  EXPECT_LT(std::abs(h.drive.velocity_rps()), 0.1);
  EXPECT_EQ(h.act.zsw1, 0x0231);
}

TEST(ProfidriveSimStateMachine, Off3QuickStopsToS1AndNeedsOnLowAgain) {
  Harness h(config_for(1));
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;
  h.cycles(200);
  h.send(stw1_word::kQuickStop | stw1::kEnableOperation);  // bit 2 low
  EXPECT_EQ(h.drive.state(), State::S5QuickStop);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kNoQuickStop));
  EXPECT_EQ(decode_state(h.act.zsw1, h.sp.stw1).state, core::AxisState::QuickStopActive);
  // 50 rev/s on the 5000 rev/s^2 quick stop ramp: about 10 ms.
  ASSERT_TRUE(h.until([&] { return h.drive.state() == State::S1SwitchingOnInhibited; }, 40));
  h.send(0x040F);  // bits 1, 2 back but ON still high: S1 stays [§7]
  h.cycles(5);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
  h.send(0x0406);
  EXPECT_EQ(h.drive.state(), State::S2ReadyForSwitchingOn);
}

TEST(ProfidriveSimStateMachine, Off2CoastsToS1AtOnceAndDisableOperationToS3) {
  Harness h(config_for(1));
  h.enable(stw1::kSpeedRunBits);
  h.send(kRun & ~stw1::kEnableOperation);
  EXPECT_EQ(h.drive.state(), State::S3SwitchedOn);
  h.send(kRun);
  EXPECT_EQ(h.drive.state(), State::S4Operation);
  h.sp.nsoll_a = 0x2000;
  h.cycles(200);
  h.send(stw1_word::kCoastStop);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
  EXPECT_GT(h.drive.velocity_rps(), 40.0);  // coasting, no braking ramp
}

// --- Faults --------------------------------------------------------------------------------------

TEST(ProfidriveSimFaults, AcknowledgeEdgeLandsInS1AndOnMustGoLow) {
  // §18.2, §25.17: the 0->1 edge of bit 7 clears the fault and the drive goes to S1; a controller
  // that holds ON stays there.
  Harness h(config_for(1));
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;
  h.cycles(200);
  h.drive.inject_fault(501);
  h.cycle();
  EXPECT_EQ(h.drive.state(), State::Fault);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kFault));
  EXPECT_EQ(decode_state(h.act.zsw1, kRun).state, core::AxisState::Fault);
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.1; }, 100));  // the drive stops
  h.send(kRun | stw1::kFaultAcknowledge);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kFault));
  h.cycles(10);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);  // ON held: no way on
  // A second fault while bit 7 stays high is not acknowledged: it needs a new edge.
  h.drive.inject_fault(502);
  h.cycles(3);
  EXPECT_EQ(h.drive.state(), State::Fault);
  h.send(0x0406);
  EXPECT_EQ(h.drive.state(), State::Fault);
  h.send(stw1_word::kFaultAcknowledge);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
  h.send(0x0406);
  EXPECT_EQ(h.drive.state(), State::S2ReadyForSwitchingOn);
}

TEST(ProfidriveSimFaults, PersistentCauseBlocksTheAcknowledge) {
  Harness h(config_for(1));
  h.send(0x0400);
  h.drive.inject_fault(231, true);
  h.send(0x0400);
  h.send(0x0480);
  EXPECT_EQ(h.drive.state(), State::Fault);
  h.drive.clear_fault_causes();
  h.send(0x0400);
  h.send(0x0480);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
}

TEST(ProfidriveSimFaults, FaultBufferSituationsShiftOnAcknowledge) {
  // §18.2: PNU 944 counts situations; a situation holds up to 8 faults in subindex 0..7; the
  // acknowledge moves it up by 8.
  Harness h(config_for(1));
  h.send(0x0400);
  h.drive.inject_fault(501);
  h.drive.inject_fault(502);
  h.drive.inject_fault(501);  // already in this situation
  EXPECT_EQ(h.drive.fault_counter(), 1U);
  EXPECT_EQ(h.drive.fault_numbers()[0], 501U);
  EXPECT_EQ(h.drive.fault_numbers()[1], 502U);
  EXPECT_EQ(h.drive.fault_numbers()[2], 0U);
  h.send(0x0480);
  EXPECT_EQ(h.drive.fault_numbers()[0], 0U);
  EXPECT_EQ(h.drive.fault_numbers()[8], 501U);
  EXPECT_EQ(h.drive.fault_numbers()[9], 502U);
  h.drive.inject_fault(702);
  EXPECT_EQ(h.drive.fault_counter(), 2U);
  EXPECT_EQ(h.drive.fault_numbers()[0], 702U);
  EXPECT_EQ(h.drive.fault_numbers()[8], 501U);
  // Eight more situations: only the newest 8 stay.
  for (std::uint16_t n = 0; n < 8; ++n) {
    h.send(0x0400);
    h.send(0x0480);
    h.drive.inject_fault(static_cast<std::uint16_t>(900 + n));
  }
  EXPECT_EQ(h.drive.fault_counter(), 10U);
  EXPECT_EQ(h.drive.fault_numbers()[0], 907U);
  EXPECT_EQ(h.drive.fault_numbers()[48], 901U);
  EXPECT_EQ(h.drive.fault_numbers()[56], 900U);  // 702 and 501 have dropped out
}

TEST(ProfidriveSimFaults, LostOutputsRaiseF702AndStopTheMotor) {
  // §18.3: communication lost is F702; the drive stops and waits for an acknowledge.
  Harness h(config_for(1));
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;
  h.cycles(200);
  h.drive.set_outputs(Outputs::Lost);
  h.cycle();
  EXPECT_EQ(h.drive.state(), State::Fault);
  EXPECT_EQ(h.drive.fault_numbers()[0], fault_number::kCommunicationLost);
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.1; }, 100));
  EXPECT_GT(h.drive.counters().invalid_outputs, 0U);
  h.drive.set_outputs(Outputs::Valid);
  h.send(0x0406);
  h.send(0x0486);
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
}

TEST(ProfidriveSimFaults, ControllerStopFollowsFbusParam02) {
  // §18.4: FBUS.PARAM02 bit 0 = 1 raises F702 on RUN -> STOP; with 0 the drive quick-stops to S1.
  {
    Harness h(config_for(1));
    h.enable(stw1::kSpeedRunBits);
    h.drive.set_outputs(Outputs::ControllerStop);
    h.cycle();
    EXPECT_EQ(h.drive.state(), State::Fault);
  }
  DriveModelConfig c = config_for(1);
  c.fbus_param02 = 0;
  Harness h(c);
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;
  h.cycles(200);
  h.drive.set_outputs(Outputs::ControllerStop);
  h.cycle();
  EXPECT_EQ(h.drive.state(), State::S5QuickStop);
  ASSERT_TRUE(h.until([&] { return h.drive.state() == State::S1SwitchingOnInhibited; }, 100));
  EXPECT_EQ(h.drive.fault_counter(), 0U);
  h.drive.set_outputs(Outputs::Valid);
  h.cycles(3);  // still kRun: ON high, so S1 holds until the controller walks the enable again
  EXPECT_EQ(h.drive.state(), State::S1SwitchingOnInhibited);
}

TEST(ProfidriveSimFaults, WrongImageLengthsAreCountedDrops) {
  Harness h(config_for(1));
  h.enable(stw1::kSpeedRunBits);
  const std::array<std::uint8_t, 3> short_image{0x04, 0x00, 0x00};
  std::array<std::uint8_t, 4> actual{};
  h.drive.step(1ms, short_image, actual);
  EXPECT_EQ(h.drive.state(), State::S4Operation);  // the last setpoints stay
  EXPECT_EQ(h.drive.counters().wrong_setpoint_length, 1U);
  std::array<std::uint8_t, 6> wrong_actual{};
  const std::array<std::uint8_t, 4> good{0x04, 0x0F, 0x00, 0x00};
  h.drive.step(1ms, good, wrong_actual);
  EXPECT_EQ(h.drive.counters().wrong_actual_length, 1U);
  EXPECT_EQ(wrong_actual, (std::array<std::uint8_t, 6>{}));
}

// --- Speed mode ----------------------------------------------------------------------------------

TEST(ProfidriveSimSpeedMode, RampBitsAndReachedBits) {
  // §8.2: bit 6 low = setpoint 0, bit 5 low freezes the ramp, bit 4 low stops on the quick ramp;
  // 2^15 = 12000 rpm [§17.1]; ZSW1 bits 8/10 once the speed is there [§9.2].
  Harness h(config_for(351));
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;  // 3000 rpm = 50 rev/s, 50 ms on DRV.ACC 60000 rpm/s
  h.cycles(20);
  EXPECT_GT(h.drive.velocity_rps(), 10.0);
  EXPECT_LT(h.drive.velocity_rps(), 25.0);
  EXPECT_GT(h.act.itist_glatt, 0);  // accelerating: positive current [§17.4]
  h.send(kRun & ~stw1::kUnfreezeRampGenerator);  // frozen
  const double frozen = h.drive.velocity_rps();
  h.cycles(50);
  EXPECT_NEAR(h.drive.velocity_rps(), frozen, 1.0);
  h.send(kRun);
  h.cycles(100);
  EXPECT_NEAR(h.act.nist_a, 0x2000, 2);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kSpeedErrorInTolerance));
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kSpeedReached));
  const std::int32_t before = h.act.xist_a;
  h.cycles(100);  // 0.1 s at 50 rev/s = 5 rev = 327680 counts (telegram 351 carries XIST_A)
  EXPECT_NEAR(h.act.xist_a - before, 327680, 400);
  h.send(kRun & ~stw1::kEnableSetpoint);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kSpeedReached));
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.1; }, 100));
  h.send(kRun);
  h.cycles(100);
  h.send(kRun & ~stw1::kEnableRampGenerator);  // quick stop ramp: 5000 rev/s^2, about 10 ms
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.1; }, 20));
  EXPECT_EQ(h.drive.state(), State::S4Operation);
}

TEST(ProfidriveSimSpeedMode, JogFromStandstillOnly) {
  // §8.2, §16.5: jog 1 with bits 4..6 low at standstill runs to PNU 1004, back to 0 when dropped.
  Harness h(config_for(1));
  h.enable();
  h.send(stw1_word::kEnableOperation | stw1::kJog1);
  ASSERT_TRUE(h.until([&] { return std::abs(h.act.nist_a - 1365) <= 2; }, 500));
  h.send(stw1_word::kEnableOperation);
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.1; }, 500));
  h.send(stw1_word::kEnableOperation | stw1::kJog2);
  ASSERT_TRUE(h.until([&] { return std::abs(h.act.nist_a + 1365) <= 2; }, 500));
  h.send(stw1_word::kEnableOperation);
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.1; }, 500));
  // With the run bits set the jog bit does nothing.
  h.sp.nsoll_a = 0;
  h.send(kRun | stw1::kJog1);
  h.cycles(100);
  EXPECT_LT(std::abs(h.drive.velocity_rps()), 0.1);
}

// --- Position mode -------------------------------------------------------------------------------

// Telegram 9 axis in S4, homed with HOME.MODE 0 (the current position) [§16.4].
void enable_and_home(Harness& h) {
  h.enable();
  h.send(kHoming);
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kHomed); }, 50));
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kTargetReached));
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kDriveStopped));
  h.send(stw1_word::kEnableOperation);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kHomed));
}

void load_mdi(Harness& h, std::int32_t target, double rpm, double rpm_per_s, bool absolute) {
  h.sp.satzanw = 0x8000;
  h.sp.mdi_tarpos = target;
  h.sp.mdi_velocity = mdi_velocity_from_rpm(rpm).value_or(0);
  h.sp.mdi_acc = mdi_acc_from_rpm_per_s(rpm_per_s).value_or(0);
  h.sp.mdi_dec = h.sp.mdi_acc;
  h.sp.mdi_mod = absolute ? 1 : 0;
}

TEST(ProfidriveSimPositionMode, MdiHandshakeAndTargetReached) {
  // §16.3: SATZANW bit 15, MDI values, 0x043F then the rising edge 0x047F; ZSW1 bit 12 follows
  // bit 6, bit 14 while the task runs, bit 13 low while moving, bit 10 at the target.
  Harness h(config_for(9));
  enable_and_home(h);
  load_mdi(h, 2 * 65536, 600.0, 6000.0, true);
  h.send(kTaskReady);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
  h.send(kTaskGo);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kMotionTaskActive));
  EXPECT_EQ(h.act.aktsatz, 0x8000);
  h.cycles(50);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kDriveStopped));
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTargetReached));
  h.send(kTaskReady);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));  // a level handshake [§25.9]
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kTargetReached); }, 2000));
  EXPECT_NEAR(h.act.xist_a, 2 * 65536, 100);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kMotionTaskActive));
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kDriveStopped); }, 200));
  // Relative: one more revolution from there.
  load_mdi(h, 65536, 600.0, 6000.0, false);
  h.send(kTaskGo);
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kTargetReached); }, 2000));
  EXPECT_NEAR(h.act.xist_a, 3 * 65536, 100);
}

// OFF1 after an MDI move: the drive at its target ramps (nothing to ramp) and reaches S2.
// At a 1 ms update and at the AKD's own minimum of 16 ms [§2]: the motor settles on the target
// (the drive's loops run faster than the telegram), so OFF1 finds standstill and reaches S2.
TEST(ProfidriveSimPositionMode, Off1AfterAnMdiMoveReachesS2) {
  for (const core::Duration update : {core::Duration(1ms), core::Duration(16ms)}) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(update).count();
    SCOPED_TRACE(testing::Message() << "update " << ms << " ms");
    Harness h(config_for(9), update);
    enable_and_home(h);
    load_mdi(h, 2 * 65536, 600.0, 6000.0, true);
    h.send(kTaskReady);
    h.send(kTaskGo);
    h.send(kTaskReady);
    ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kTargetReached); }, 2000));
    ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kDriveStopped); }, 200));
    EXPECT_NEAR(h.act.xist_a, 2 * 65536, 16);
    h.send(0x0406);
    ASSERT_TRUE(h.until([&] { return h.drive.state() == State::S2ReadyForSwitchingOn; }, 2000))
        << "state " << static_cast<int>(h.drive.state()) << " velocity " << h.drive.velocity_rps() << " ZSW1 0x"
        << std::hex << h.act.zsw1;
  }
}

TEST(ProfidriveSimPositionMode, MdiOnTheFlyChangeAndReject) {
  Harness h(config_for(9));
  enable_and_home(h);
  load_mdi(h, 10 * 65536, 600.0, 6000.0, true);
  h.send(kTaskReady);
  h.send(kTaskGo);
  h.cycles(100);
  // §16.3 on-the-fly: bit 6 down, bit 12 follows, new values, bit 6 up.
  h.send(kTaskReady);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
  load_mdi(h, -65536, 600.0, 6000.0, true);
  h.send(kTaskGo);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kTargetReached); }, 3000));
  EXPECT_NEAR(h.act.xist_a, -65536, 100);
  // Bit 4 low rejects the running task: the drive stops short of the target, no target reached.
  h.send(kTaskReady);
  load_mdi(h, 10 * 65536, 600.0, 6000.0, true);
  h.send(kTaskGo);
  h.cycles(100);
  h.send(kTaskGo & ~stw1::kDoNotRejectTask);
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kDriveStopped); }, 500));
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTargetReached));
  EXPECT_LT(h.act.xist_a, 5 * 65536);
  // A task without velocity is not acknowledged [§16.3].
  h.send(kTaskReady);
  load_mdi(h, 0, 0.0, 6000.0, true);
  h.send(kTaskGo);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
}

TEST(ProfidriveSimPositionMode, TaskBeforeHomingIsNotAcknowledged) {
  // §16.2, §16.3: the axis must be homed.
  Harness h(config_for(9));
  h.enable();
  load_mdi(h, 65536, 600.0, 6000.0, true);
  h.send(kTaskReady);
  h.send(kTaskGo);
  h.cycles(10);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
  EXPECT_LT(std::abs(h.drive.velocity_rps()), 0.01);
}

TEST(ProfidriveSimPositionMode, ProgramModeWithIntermediateStop) {
  // §16.2: telegram 7, SATZANW = the task, 0x043F then the edge; bit 5 low stops in between and
  // back to 1 goes on; AKTSATZ reports the task.
  DriveModelConfig c = config_for(7);
  c.motion_tasks[3] = MotionTask{4 * 65536, mdi_velocity_from_rpm(600.0).value_or(0),
                                 mdi_acc_from_rpm_per_s(6000.0).value_or(0), mdi_acc_from_rpm_per_s(6000.0).value_or(0), 1};
  Harness h(c);
  enable_and_home(h);
  h.sp.satzanw = 3;
  h.send(kTaskReady);
  h.send(kTaskGo);
  EXPECT_EQ(h.act.aktsatz, 3);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kMotionTaskActive));
  h.cycles(150);
  h.send(kTaskGo & ~stw1::kNoIntermediateStop);
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.05; }, 500));
  const double stopped_at = h.drive.position_rev();
  h.cycles(100);
  EXPECT_NEAR(h.drive.position_rev(), stopped_at, 0.01);
  EXPECT_LT(stopped_at, 3.5);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kMotionTaskActive));
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTargetReached));
  h.send(kTaskGo);
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kTargetReached); }, 2000));
  EXPECT_NEAR(h.drive.position_rev(), 4.0, 0.002);
  // An unconfigured task is not acknowledged.
  h.send(kTaskReady);
  h.sp.satzanw = 5;
  h.send(kTaskGo);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
}

TEST(ProfidriveSimPositionMode, HomingOnTheSwitchWithHomeDistFromTelegram353) {
  // §16.4: bit 11 starts, bits 10/11/13 all 0 while homing runs and all 1 at the end; HOME_MODE
  // and HOME_DIST come cyclically in telegram 353 [§14.8]. The reference point is HOME.P.
  DriveModelConfig c = config_for(353);
  c.home_switch_rev = 1.5;
  c.home_position_counts = 1000;
  Harness h(c);
  h.enable();
  h.sp.home_mode = 4;
  h.sp.home_dist = 16384;
  h.send(kHoming);
  h.cycles(5);
  EXPECT_EQ(h.act.zsw1 & (zsw1::kTargetReached | zsw1::kHomed | zsw1::kDriveStopped), 0);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kMotionTaskActive));
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kHomed); }, 3000));
  EXPECT_EQ(h.act.zsw1 & (zsw1::kTargetReached | zsw1::kHomed | zsw1::kDriveStopped),
            zsw1::kTargetReached | zsw1::kHomed | zsw1::kDriveStopped);
  EXPECT_NEAR(h.act.xist_a, 1000 + 16384, 50);
  // A second homing aborted by clearing bit 11: bit 11 stays 0 [§16.4].
  h.send(stw1_word::kEnableOperation);
  h.send(kHoming);
  h.cycles(5);
  h.send(stw1_word::kEnableOperation);
  h.cycles(100);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kHomed));
  EXPECT_FALSE(h.drive.homed());
}

TEST(ProfidriveSimPositionMode, Telegram352TakesHomeModeFromPnu1001) {
  // Telegram 352 carries HOME_DIST but not HOME_MODE [§14.7]: the mode is PNU 1001 (= HOME.MODE).
  DriveModelConfig c = config_for(352);
  c.home_switch_rev = -0.75;  // behind the motor: found at once, as the search runs upwards
  Harness h(c);
  EXPECT_TRUE(h.change(1001, format::kWord, 4).positive());
  EXPECT_EQ(h.value(2203), 4U);
  EXPECT_EQ(h.change(1001, format::kWord, 7).blocks[0].error_number(), 0x02);  // not modelled
  h.enable();
  h.sp.home_dist = -32768;
  h.send(kHoming);
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kHomed); }, 3000));
  EXPECT_NEAR(h.act.xist_a, -32768, 50);
  EXPECT_EQ(h.value(2198), static_cast<std::uint32_t>(-32768));  // HOME.DIST as last used
}

TEST(ProfidriveSimSpeedMode, Telegram350ReportsTheCurrent) {
  // §14.5, §17.4: ITIST_GLATT, 2^14 = DRV.IPEAK, signed: negative while braking.
  Harness h(config_for(350));
  ASSERT_EQ(h.drive.layout().actual_bytes(), 6U);
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x2000;
  h.cycles(200);
  h.sp.nsoll_a = 0;
  h.cycles(10);
  EXPECT_LT(h.act.itist_glatt, -1000);
}

TEST(ProfidriveSimPositionMode, UnsupportedHomingModeWarns) {
  Harness h(config_for(353));
  h.enable();
  h.sp.home_mode = 4;  // no home switch configured
  h.send(kHoming);
  h.cycles(5);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kWarning));
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kHomed));
  h.send(stw1_word::kEnableOperation);
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kWarning));
}

TEST(ProfidriveSimPositionMode, RealTimeJogUsesTheMdiSignals) {
  // §8.3, §16.5: bit 12 jogs with MDI_VELOCITY/ACC/DEC, bit 13 sets counter-clockwise.
  Harness h(config_for(9));
  h.enable();
  load_mdi(h, 0, 600.0, 6000.0, true);
  h.send(stw1_word::kEnableOperation | stw1::kRealTimeJog | stw1::kRealTimeJogCcw);
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps() + 10.0) < 0.01; }, 1000));
  h.send(stw1_word::kEnableOperation);
  ASSERT_TRUE(h.until([&] { return std::abs(h.drive.velocity_rps()) < 0.01; }, 1000));
  EXPECT_LT(h.act.xist_a, 0);
}

TEST(ProfidriveSimPositionMode, BlockedMotorRaisesFollowingError) {
  // PL.ERRWTHRESH exceeded: ZSW1 bit 8 low; PL.ERRFTHRESH exceeded: F439 into the fault buffer, ZSW1
  // bit 3 [§9.3, §18.2].
  Harness h(config_for(9));
  enable_and_home(h);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kFollowingErrorInTolerance));
  h.drive.set_motor_blocked(true);
  load_mdi(h, 10 * 65536, 600.0, 6000.0, true);
  h.send(kTaskReady);
  h.send(kTaskGo);
  // Past PL.ERRWTHRESH ZSW1 bit 8 drops first (1 = within tolerance, the standard's polarity [§9.3]).
  ASSERT_TRUE(h.until([&] { return !bit(h.act.zsw1, zsw1::kFollowingErrorInTolerance); }, 1000));
  EXPECT_FALSE(bit(h.act.zsw1, zsw1::kFault));
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kFault); }, 1000));
  EXPECT_EQ(h.drive.fault_numbers()[0], fault_number::kFollowingError);
}

// --- Free telegrams ------------------------------------------------------------------------------

TEST(ProfidriveSimFreeTelegram, Telegram400DefaultIsLikeTelegram9) {
  // §13, §14.9: 12 words each way, default mapping similar to telegram 9.
  Harness h(config_for(400));
  EXPECT_EQ(h.drive.layout().setpoint_bytes(), 24U);
  EXPECT_EQ(h.drive.layout().actual_bytes(), 24U);
  enable_and_home(h);
  load_mdi(h, 65536, 600.0, 6000.0, true);
  h.send(kTaskReady);
  h.send(kTaskGo);
  EXPECT_TRUE(bit(h.act.zsw1, zsw1::kTaskAcknowledge));
  ASSERT_TRUE(h.until([&] { return bit(h.act.zsw1, zsw1::kTargetReached); }, 2000));
  EXPECT_NEAR(h.act.xist_a, 65536, 100);
}

TEST(ProfidriveSimFreeTelegram, Telegram0MappedThroughPnu915And916) {
  // §13: telegram 0's mapping is written to PNU 915/916; the image size stays the module's.
  DriveModelConfig c = config_for(0);
  c.free_setpoint_words = 2;
  c.free_actual_words = 3;
  c.pnu915[0] = 1;
  c.pnu916[0] = 2;
  c.operating_mode = OperatingMode::Speed;
  Harness h(c);
  ASSERT_EQ(h.drive.layout().setpoint_bytes(), 4U);
  EXPECT_TRUE(h.change(915, format::kWord, 5, 1).positive());   // word 2: NSOLL_A
  EXPECT_TRUE(h.change(916, format::kWord, 52, 1).positive());  // word 2: ITIST_GLATT
  EXPECT_TRUE(h.change(916, format::kWord, 6, 2).positive());   // word 3: NIST_A
  EXPECT_TRUE(h.drive.layout().carries(Signal::NsollA));
  EXPECT_TRUE(h.drive.layout().carries(Signal::NistA));
  // An actual value in the setpoint list is refused (0x14) and the mapping stays.
  const ParamResponse bad = h.change(915, format::kWord, 6, 1);
  ASSERT_FALSE(bad.positive());
  EXPECT_EQ(bad.blocks[0].error_number(), 0x14);
  h.enable(stw1::kSpeedRunBits);
  h.sp.stw1 = kRun;
  h.sp.nsoll_a = 0x1000;
  h.cycles(200);
  EXPECT_NEAR(h.act.nist_a, 0x1000, 2);
  // Remapping is refused in S4 (0x11).
  const ParamResponse busy = h.change(916, format::kWord, 0, 2);
  ASSERT_FALSE(busy.positive());
  EXPECT_EQ(busy.blocks[0].error_number(), 0x11);
}

TEST(ProfidriveSimFreeTelegram, ConfigurationErrorsAreReported) {
  DriveModelConfig c = config_for(2);  // no such telegram
  EXPECT_EQ(DriveModel(c).layout_error(), TelegramError::UnknownTelegram);
  c = config_for(0);
  c.free_setpoint_words = 2;
  c.pnu915[0] = 1;
  c.pnu915[1] = 34;  // MDI_TARPOS needs two words
  DriveModel d(c);
  EXPECT_EQ(d.layout_error(), TelegramError::SplitSignal);
  const std::array<std::uint8_t, 4> image{0x04, 0x06, 0x00, 0x00};
  std::array<std::uint8_t, 2> actual{};
  d.step(1ms, image, actual);
  EXPECT_EQ(d.counters().wrong_setpoint_length, 1U);
  EXPECT_EQ(d.state(), State::S1SwitchingOnInhibited);
  c.pnu915[1] = 0;
  EXPECT_EQ(DriveModel(c).layout_error(), TelegramError::None);  // STW1 / ZSW1 and an unused word
}

// --- Cycle-thread rules --------------------------------------------------------------------------

TEST(ProfidriveSimCycle, StepAndRecordsDoNotAllocate) {
  DriveModelConfig c = config_for(9);
  Harness h(c);
  std::array<std::uint8_t, 20> out{};
  std::array<std::uint8_t, 10> in{};
  const std::array<std::uint8_t, 10> read947{0x08, 0x01, 0x00, 0x01, 0x10, 0x40, 0x03, 0xB3, 0x00, 0x00};
  std::array<std::uint8_t, kMaxParamRecord> response{};
  Setpoints sp;
  const std::uint16_t words[] = {0x0400, 0x0406, 0x0407, 0x040F, 0x0C0F, 0x040F, 0x043F, 0x047F};
  drivegate::test::AllocationScope scope;
  for (const std::uint16_t w : words) {
    sp.stw1 = w;
    sp.satzanw = 0x8000;
    sp.mdi_tarpos = 65536;
    sp.mdi_velocity = 0x01000000;
    sp.mdi_acc = sp.mdi_dec = 10;
    (void)encode_setpoints(h.drive.layout(), sp, out);
    for (int i = 0; i < 20; ++i) h.drive.step(1ms, out, in);
  }
  h.drive.inject_fault(702);
  h.drive.set_outputs(Outputs::Lost);
  for (int i = 0; i < 20; ++i) h.drive.step(1ms, out, in);
  EXPECT_EQ(h.drive.write_parameter_record(read947), RecordStatus::Ok);
  EXPECT_EQ(h.drive.read_parameter_record(response).status, RecordStatus::Ok);
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_TRUE(h.drive.homed());
}

}  // namespace
}  // namespace drivegate::profidrive::sim::test
