// STW1/ZSW1 state machine against akd-profinet-profidrive.md §7, §9.4, §15.1, §20.2, §20.3.
#include "profiles/profidrive/state_machine.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "profiles/profidrive/control_words.hpp"

namespace drivegate::profidrive {
namespace {

using core::AxisState;

// ZSW1 patterns per state [§7 table, §9.4]: bits 9 (control requested), 4 and 5 (no OFF2/OFF3) set.
constexpr std::uint16_t kS1 = 0x0270;  // bit 6, bits 4/5 following STW1 bits 1/2
constexpr std::uint16_t kS2 = 0x0231;
constexpr std::uint16_t kS3 = 0x0233;
constexpr std::uint16_t kS4 = 0x0237;  // the only documented value [§20.3]

TEST(ProfidriveState, ControlWordValuesFromTheDigest) {
  // §20.2 recommended sequence and §15.1 with the ramp bits.
  EXPECT_EQ(stw1_word::kIdle, 0x0400);
  EXPECT_EQ(stw1_word::kShutdown, 0x0406);
  EXPECT_EQ(stw1_word::kSwitchOn, 0x0407);
  EXPECT_EQ(stw1_word::kEnableOperation, 0x040F);
  EXPECT_EQ(stw1_word::kSpeedRun, 0x047F);
  EXPECT_EQ(stw1_word::kShutdown | stw1::kSpeedRunBits, 0x0476);
  EXPECT_EQ(stw1_word::kSwitchOn | stw1::kSpeedRunBits, 0x0477);
  // §16.2/§16.3 position mode, §16.4 homing, §16.5 jog.
  EXPECT_EQ(stw1_word::kTaskReady, 0x043F);
  EXPECT_EQ(stw1_word::kTaskActivate, 0x047F);
  EXPECT_EQ(stw1_word::kHoming, 0x0C0F);
  EXPECT_EQ(stw1_word::kEnableOperation | stw1::kJog1, 0x050F);
  EXPECT_EQ(stw1_word::kEnableOperation | stw1::kJog2, 0x060F);
  // Every word the gateway sends has bit 10 (control by PLC) [§8.1].
  for (const std::uint16_t w : {stw1_word::kIdle, stw1_word::kShutdown, stw1_word::kSwitchOn,
                                stw1_word::kEnableOperation, stw1_word::kSpeedRun, stw1_word::kQuickStop,
                                stw1_word::kCoastStop, stw1_word::kFaultAcknowledge, stw1_word::kTaskReady,
                                stw1_word::kTaskActivate, stw1_word::kHoming}) {
    EXPECT_NE(w & stw1::kControlByPlc, 0) << std::hex << w;
  }
}

TEST(ProfidriveState, S1ToS4) {
  EXPECT_EQ(decode_state(kS1, 0x0400), (DriveState{AxisState::SwitchOnDisabled, false}));
  EXPECT_EQ(decode_state(0x0240, 0x0400), (DriveState{AxisState::SwitchOnDisabled, false}));  // bits 4/5 low in S1
  EXPECT_EQ(decode_state(kS2, 0x0406), (DriveState{AxisState::ReadyToSwitchOn, false}));
  EXPECT_EQ(decode_state(kS3, 0x0407), (DriveState{AxisState::SwitchedOn, false}));
  EXPECT_EQ(decode_state(kS4, 0x040F), (DriveState{AxisState::OperationEnabled, false}));
  EXPECT_EQ(decode_state(kS4, 0x047F), (DriveState{AxisState::OperationEnabled, false}));
}

TEST(ProfidriveState, S5AfterOff1IsStoppingTowardsS2) {
  // OFF1 in S4: the drive ramps down (S5) and reaches S2 at standstill [§7].
  EXPECT_EQ(decode_state(kS4, 0x0406), (DriveState{AxisState::ReadyToSwitchOn, true}));
  EXPECT_EQ(decode_state(kS3, 0x0406), (DriveState{AxisState::ReadyToSwitchOn, true}));
  EXPECT_EQ(decode_state(kS2, 0x0406), (DriveState{AxisState::ReadyToSwitchOn, false}));
}

TEST(ProfidriveState, S5AfterOff3IsQuickStop) {
  // ZSW1 bit 5 low: quick stop active; then S1 at standstill [§7].
  EXPECT_EQ(decode_state(kS4 & ~zsw1::kNoQuickStop, 0x040B), (DriveState{AxisState::QuickStopActive, true}));
  EXPECT_EQ(decode_state(kS3 & ~zsw1::kNoQuickStop, stw1_word::kQuickStop),
            (DriveState{AxisState::QuickStopActive, true}));
  EXPECT_EQ(decode_state(0x0250, stw1_word::kQuickStop), (DriveState{AxisState::SwitchOnDisabled, false}));
  // OFF3 just sent, the drive still in S4: quick stop under way, not the OFF1 ramp (bit 0 is low
  // too in 0x0402).
  EXPECT_EQ(decode_state(kS4, stw1_word::kQuickStop), (DriveState{AxisState::QuickStopActive, true}));
}

TEST(ProfidriveState, CoastStopAndFault) {
  EXPECT_EQ(decode_state(kS4 & ~zsw1::kNoCoastStop, 0x0400), (DriveState{AxisState::SwitchOnDisabled, true}));
  // The fault bit wins over every other pattern.
  EXPECT_EQ(decode_state(kS4 | zsw1::kFault, 0x047F), (DriveState{AxisState::Fault, false}));
  EXPECT_EQ(decode_state(0x0248, 0x0400), (DriveState{AxisState::Fault, false}));
  EXPECT_EQ(decode_state(0x0000, 0x0000), (DriveState{AxisState::NotReadyToSwitchOn, false}));
  EXPECT_EQ(decode_state(0x0232, 0x0407), (DriveState{AxisState::Unknown, false}));  // ready to operate alone
}

TEST(ProfidriveState, SteadyStateVectorOfTheS7Example) {
  // §20.3: ZSW1 0x0237, STW1 0x047F: S4, no warning, bits 8 and 10 false, bit 9 true.
  const DriveState s = decode_state(0x0237, 0x047F);
  EXPECT_EQ(s.state, AxisState::OperationEnabled);
  const Zsw1Flags f = decode_flags(0x0237);
  EXPECT_FALSE(f.warning);
  EXPECT_TRUE(f.control_requested);
  EXPECT_FALSE(f.bit8_in_tolerance);
  EXPECT_FALSE(f.bit10_reached);
  const Zsw1Flags homed = decode_flags(0x0237 | zsw1::kTargetReached | zsw1::kHomed | zsw1::kDriveStopped);
  EXPECT_TRUE(homed.bit10_reached);
  EXPECT_TRUE(homed.homed);
  EXPECT_TRUE(homed.drive_stopped);
  EXPECT_FALSE(homed.task_acknowledge);
}

// Runs the enable walk against a drive that follows STW1 as §7 describes, one transition a cycle.
struct ModelDrive {
  std::uint16_t state = 1;  // 1..4, 0 = fault
  std::uint16_t last = 0;
  std::uint16_t zsw1() const {
    switch (state) {
      case 0: return 0x0248;
      case 1: return kS1;
      case 2: return kS2;
      case 3: return kS3;
      default: return kS4;
    }
  }
  void apply(std::uint16_t stw1) {
    const bool ack_edge = (stw1 & stw1::kFaultAcknowledge) != 0 && (last & stw1::kFaultAcknowledge) == 0;
    last = stw1;
    ASSERT_NE(stw1 & stw1::kControlByPlc, 0);
    const bool on = (stw1 & stw1::kOn) != 0, off2 = (stw1 & stw1::kNoCoastStop) != 0,
               off3 = (stw1 & stw1::kNoQuickStop) != 0, op = (stw1 & stw1::kEnableOperation) != 0;
    if (state == 0) {
      if (ack_edge) state = 1;  // the AKD lands in S1 [§18.2]
      return;
    }
    if (state == 1 && !on && off2 && off3) state = 2;
    else if (state == 2 && on) state = 3;
    else if (state == 3 && op) state = 4;
  }
};

std::vector<std::uint16_t> walk(ModelDrive& d, std::uint16_t last, std::uint16_t mode_bits) {
  std::vector<std::uint16_t> sent;
  for (int i = 0; i < 10; ++i) {
    const EnableStep step = enable_step(decode_state(d.zsw1(), last), last, mode_bits);
    sent.push_back(step.stw1);
    if (step.done) break;
    d.apply(step.stw1);
    last = step.stw1;
  }
  return sent;
}

TEST(ProfidriveState, EnableWalkRecommendedSequence) {
  // §20.2 "recommended gateway sequence": 0x0406 -> 0x0407 -> 0x040F.
  ModelDrive d;
  EXPECT_EQ(walk(d, 0x0400, 0), (std::vector<std::uint16_t>{0x0406, 0x0407, 0x040F, 0x040F}));
}

TEST(ProfidriveState, EnableWalkSpeedModeSequence) {
  // §15.1 telegram 1: 0x0476 -> 0x0477 -> 0x047F (S4, the set-point is used from here on).
  ModelDrive d;
  EXPECT_EQ(walk(d, 0x0470, stw1::kSpeedRunBits), (std::vector<std::uint16_t>{0x0476, 0x0477, 0x047F, 0x047F}));
}

TEST(ProfidriveState, FaultAcknowledgeEdgeThenS1ThenOnAgain) {
  // Fault while running: bit 7 rises with bit 0 low, the drive lands in S1, then S2, S3, S4
  // [§18.2, §24 step 12, §25.17].
  ModelDrive d;
  d.state = 0;
  EXPECT_EQ(walk(d, 0x047F, 0), (std::vector<std::uint16_t>{0x0486, 0x0406, 0x0407, 0x040F, 0x040F}));
  // The last word still had bit 7 set (an acknowledge that did not take): bit 7 drops first.
  ModelDrive again;
  again.state = 0;
  again.last = 0x0486;
  EXPECT_EQ(walk(again, 0x0486, 0), (std::vector<std::uint16_t>{0x0406, 0x0486, 0x0406, 0x0407, 0x040F, 0x040F}));
}

TEST(ProfidriveState, FaultResetAloneStaysInS1) {
  EXPECT_EQ(fault_reset_stw1(true), 0x0480);
  EXPECT_EQ(fault_reset_stw1(false), 0x0400);  // bit 7 low first when the last word had it
  // Bits 0..3 low: after the acknowledge the drive stays in S1 (S1 -> S2 needs bits 1 and 2).
  EXPECT_EQ(fault_reset_stw1(true) & stw1::kStateMask, 0);
  EXPECT_NE(fault_reset_stw1(true) & stw1::kControlByPlc, 0);
}

TEST(ProfidriveState, EnableWaitsForAStopToFinish) {
  // S5 after OFF1: keep sending the stop word; quick stop: hold OFF3 with bit 0 low.
  EXPECT_EQ(enable_step(decode_state(kS4, 0x0406), 0x0406).stw1, 0x0406);
  EXPECT_FALSE(enable_step(decode_state(kS4, 0x0406), 0x0406).done);
  EXPECT_EQ(enable_step(decode_state(kS4 & ~zsw1::kNoQuickStop, 0x040B), 0x040B).stw1, stw1_word::kQuickStop);
  EXPECT_EQ(enable_step(DriveState{AxisState::Unknown, false}, 0).stw1, 0x0406);
}

}  // namespace
}  // namespace drivegate::profidrive
