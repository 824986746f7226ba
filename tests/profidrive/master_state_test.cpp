// ProfidriveMaster against the scripted drive: the general state machine (enable, disable, quick
// stop, timeouts), faults and their acknowledge, the fault buffer, a stale telegram and link loss.
#include <gtest/gtest.h>

#include <vector>

#include "tests/profidrive/master_harness.hpp"

namespace drivegate::profidrive::test {
namespace {

using core::AxisState;
using core::EventKind;
using State = ScriptedDrive::State;

TEST(ProfidriveMaster, HoldsTheDriveOffUntilCommanded) {
  Harness h(1);
  EXPECT_FALSE(h.submit(command(9, CommandKind::Enable)).accepted);  // no telegram yet
  h.run(20);
  EXPECT_EQ(h.drive.stw1(), 0x0402);  // OFF3 with bit 10: stays in S1
  EXPECT_EQ(h.drive.state, State::S1);
  EXPECT_TRUE(h.master.feedback().valid);
  EXPECT_EQ(h.master.feedback().state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.drive.last.nsoll_a, 0);
}

TEST(ProfidriveMaster, EnableWalksTheManualSequenceOneStepACycle) {
  Harness h(1);
  h.cycle();
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  std::vector<std::uint16_t> words;
  for (int i = 0; i < 8 && !h.finished(1); ++i) {
    h.cycle();
    const std::uint16_t w = h.drive.sent().stw1;
    if (words.empty() || words.back() != w) words.push_back(w);
  }
  // §15.1: 0x0476 (S1 -> S2), 0x0477 (S2 -> S3), 0x047F (S3 -> S4), bit 10 always set.
  EXPECT_EQ(words, (std::vector<std::uint16_t>{0x0476, 0x0477, 0x047F}));
  EXPECT_TRUE(h.sink.done(1));
  EXPECT_EQ(h.drive.state, State::S4);
  EXPECT_EQ(h.master.feedback().state, AxisState::OperationEnabled);
  EXPECT_EQ(h.drive.last.nsoll_a, 0);  // nothing moves until a velocity command
}

TEST(ProfidriveMaster, DisableIsOff1ThenS1AndQuickStopIsOff3ToS1) {
  Harness h(1);
  h.drive.stop_cycles = 5;
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::Disable)).accepted);
  std::vector<std::uint16_t> words;
  std::vector<State> states;
  for (int i = 0; i < 40 && !h.finished(2); ++i) {
    h.cycle();
    if (words.empty() || words.back() != h.drive.sent().stw1) words.push_back(h.drive.sent().stw1);
    if (states.empty() || states.back() != h.drive.state) states.push_back(h.drive.state);
  }
  // OFF1 ramps down through S5 to S2 with no OFF3 in between, then bit 2 low takes S2 to S1 [§7]:
  // "disabled" is switch_on_disabled on every bus.
  EXPECT_EQ(words, (std::vector<std::uint16_t>{0x0406, 0x0402}));
  EXPECT_EQ(states, (std::vector<State>{State::S4, State::S5Off1, State::S2, State::S1}));
  EXPECT_TRUE(h.sink.done(2));
  EXPECT_EQ(h.master.feedback().state, AxisState::SwitchOnDisabled);
  h.run(20);
  EXPECT_EQ(h.drive.state, State::S1);  // bit 0 low: it stays there

  ASSERT_TRUE(h.submit(command(3, CommandKind::Enable)).accepted);
  ASSERT_TRUE(h.wait(3));
  ASSERT_TRUE(h.submit(command(4, CommandKind::QuickStop)).accepted);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x0402);
  ASSERT_TRUE(h.wait(4));
  EXPECT_TRUE(h.sink.done(4));
  EXPECT_EQ(h.drive.state, State::S1);
  h.run(20);
  EXPECT_EQ(h.drive.state, State::S1);  // bit 0 low: it stays there
}

TEST(ProfidriveMaster, EnableTimesOutNamingTheStep) {
  MasterSettings s;
  s.step_timeout = 50ms;
  Harness h(1, s);
  h.drive.stuck_in_s1 = true;
  h.cycle();
  ASSERT_TRUE(h.submit(command(1, CommandKind::Enable)).accepted);
  ASSERT_TRUE(h.wait(1, 200));
  const std::string why = h.sink.failure(1);
  EXPECT_NE(why.find("S1 switching on inhibited"), std::string::npos) << why;
  EXPECT_NE(why.find("S1 -> S2"), std::string::npos) << why;
  EXPECT_NE(why.find("0x0476"), std::string::npos) << why;
  h.cycle();
  EXPECT_EQ(h.drive.stw1(), 0x0402);  // the walk is taken back
}

TEST(ProfidriveMaster, FaultFailsCommandsReadsTheBufferAndResetLandsInS1) {
  Harness h(1);
  static constexpr FaultText kTable[] = {{702, "Fieldbus communication lost"}, {501, "Bus overvoltage"}};
  h.master.set_fault_table(kTable);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, kOneRps)).accepted);
  h.run(3);
  h.drive.raise_fault({702, 501});
  h.run(2);
  EXPECT_NE(h.sink.failure(2).find("drive fault"), std::string::npos);
  EXPECT_EQ(h.master.feedback().state, AxisState::Fault);
  EXPECT_EQ(h.drive.last.nsoll_a, 0);
  ASSERT_TRUE(h.run_until([&] { return h.sink.count(EventKind::Fault) == 2; }, 100));
  std::vector<std::uint32_t> codes;
  for (const auto& e : h.sink.events) {
    if (e.kind == EventKind::Fault) codes.push_back(e.code);
  }
  EXPECT_EQ(codes, (std::vector<std::uint32_t>{702, 501}));
  EXPECT_EQ(h.master.feedback().fault_code, 702U);
  EXPECT_EQ(h.master.feedback().fault_text.view(), "F702: Fieldbus communication lost");
  // The plan was 944 -> 947 -> 944: three requests.
  EXPECT_EQ(h.drive.requests, 3);

  EXPECT_FALSE(h.submit(command(3, CommandKind::Enable)).accepted);  // reset first
  ASSERT_TRUE(h.submit(command(4, CommandKind::FaultReset)).accepted);
  std::vector<std::uint16_t> words;
  ASSERT_TRUE(h.run_until([&] {
    words.push_back(h.drive.sent().stw1);
    return h.finished(4);
  }));
  EXPECT_TRUE(h.sink.done(4));
  // A 0->1 edge on bit 7 with bits 0..3 low [§8.1, §25.17].
  bool edge = false;
  for (std::size_t i = 1; i < words.size(); ++i)
    edge = edge || ((words[i] & 0x0080) != 0 && (words[i - 1] & 0x0080) == 0 && (words[i] & 0x000F) == 0);
  EXPECT_TRUE(edge);
  EXPECT_EQ(h.drive.state, State::S1);
  EXPECT_EQ(h.sink.count(EventKind::FaultCleared), 1U);
  EXPECT_EQ(h.master.feedback().fault_code, 0U);
  h.run(10);
  EXPECT_EQ(h.drive.state, State::S1);  // acknowledged, not re-enabled

  // Enable again from S1: bit 0 low first (S2), then on.
  ASSERT_TRUE(h.submit(command(5, CommandKind::Enable)).accepted);
  ASSERT_TRUE(h.wait(5));
  EXPECT_TRUE(h.sink.done(5));
  EXPECT_EQ(h.drive.state, State::S4);
}

// Over PROFINET the drive takes STW1 once per update time (16 controller cycles here), whatever
// the cycle a fault reset starts in: bit 7 is held high until the drive leaves its fault, not
// toggled every cycle (toggled, every frame of an even reduction ratio carried the same level, and
// in half the phases the drive never saw the edge).
TEST(ProfidriveMaster, FaultResetHoldsTheAcknowledgeForADriveThatTakesStw1OncePerUpdateTime) {
  for (int phase = 0; phase < 16; ++phase) {
    Harness h(1);
    h.enable();
    h.drive.raise_fault({501});
    ASSERT_TRUE(h.run_until([&] { return h.sink.count(EventKind::Fault) == 1; }, 100));
    ASSERT_TRUE(h.submit(command(2, CommandKind::FaultReset)).accepted);
    for (int i = 0; i < 3000 && !h.finished(2); ++i) {
      const bool takes = (i + phase) % 16 == 0;
      if (takes) h.drive.step();
      h.drive.fresh = takes;
      h.master.update(h.now, h.sink);
      h.now += 1ms;
    }
    EXPECT_TRUE(h.sink.done(2)) << "phase " << phase << ": " << h.sink.failure(2);
    EXPECT_EQ(h.drive.state, State::S1) << "phase " << phase;
  }
}

TEST(ProfidriveMaster, FaultResetTimesOutWhileTheCauseStays) {
  MasterSettings s;
  s.step_timeout = 40ms;
  Harness h(1, s);
  h.enable();
  h.drive.fault_persists = true;
  h.drive.raise_fault({702});
  h.run(3);
  ASSERT_TRUE(h.submit(command(2, CommandKind::FaultReset)).accepted);
  ASSERT_TRUE(h.wait(2, 200));
  EXPECT_NE(h.sink.failure(2).find("fault acknowledge"), std::string::npos) << h.sink.failure(2);
}

TEST(ProfidriveMaster, UnreadableFaultBufferStillReportsTheFault) {
  Harness h(1);
  h.enable();
  h.drive.param_rpc_fails = true;
  h.drive.raise_fault({702});
  ASSERT_TRUE(h.run_until([&] { return h.sink.count(EventKind::Fault) == 1; }, 100));
  EXPECT_NE(h.master.feedback().fault_text.view().find("fault buffer unreadable: record 47 exchange failed"),
            std::string_view::npos)
      << h.master.feedback().fault_text.view();
}

TEST(ProfidriveMaster, DisableInFaultCompletesAtOnce) {
  Harness h(1);
  h.enable();
  h.drive.raise_fault({702});
  h.run(2);
  ASSERT_TRUE(h.submit(command(2, CommandKind::Disable)).accepted);
  EXPECT_TRUE(h.sink.done(2));
}

TEST(ProfidriveMaster, DriveLeavingS4OnItsOwnFailsTheMotionAndStaysOff) {
  Harness h(1);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, kOneRps)).accepted);
  h.run(3);
  h.drive.state = State::S1;  // STO
  h.run(3);
  EXPECT_NE(h.sink.failure(2).find("left S4 on its own"), std::string::npos) << h.sink.failure(2);
  h.run(10);
  EXPECT_EQ(h.drive.state, State::S1);
  EXPECT_EQ(h.drive.stw1(), 0x0402);
}

TEST(ProfidriveMaster, DriveNotFollowingStw1IsControlLost) {
  MasterSettings s;
  s.follow_timeout = 30ms;
  s.stop_timeout = 100ms;
  Harness h(1, s);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, kOneRps)).accepted);
  ASSERT_TRUE(h.wait(2));
  h.drive.ignores_stw1 = true;  // taken over locally: ZSW1 bit 9 drops, STW1 does nothing
  ASSERT_TRUE(h.submit(command(3, CommandKind::QuickStop)).accepted);
  h.run(20);
  EXPECT_EQ(h.sink.count(EventKind::ControlLost), 0U);  // not yet: within follow_timeout
  EXPECT_GE(h.sink.count(EventKind::Info), 1U);       // bit 9 went low
  h.run(20);
  ASSERT_EQ(h.sink.count(EventKind::ControlLost), 1U);
  EXPECT_EQ(h.drive.control_lost_calls, 1);
  for (const auto& e : h.sink.events) {
    if (e.kind == EventKind::ControlLost) {
      EXPECT_NE(e.text.find("does not follow STW1"), std::string::npos) << e.text;
    }
  }
  ASSERT_TRUE(h.wait(3, 200));
  EXPECT_NE(h.sink.failure(3).find("quick_stop: drive stayed in"), std::string::npos) << h.sink.failure(3);
  EXPECT_NE(h.sink.failure(3).find("OFF3 to S1"), std::string::npos) << h.sink.failure(3);
  h.run(100);
  EXPECT_EQ(h.drive.control_lost_calls, 1);  // once per loss
}

TEST(ProfidriveMaster, Off1RampIsNotControlLoss) {
  MasterSettings s;
  s.follow_timeout = 2ms;
  Harness h(1, s);
  h.drive.stop_cycles = 50;
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::QuickStop)).accepted);
  ASSERT_TRUE(h.wait(2));
  ASSERT_TRUE(h.submit(command(3, CommandKind::Enable)).accepted);
  ASSERT_TRUE(h.wait(3));
  ASSERT_TRUE(h.submit(command(4, CommandKind::Disable)).accepted);
  ASSERT_TRUE(h.wait(4));
  EXPECT_TRUE(h.sink.done(2));
  EXPECT_TRUE(h.sink.done(4));
  EXPECT_EQ(h.sink.count(EventKind::ControlLost), 0U);
}

TEST(ProfidriveMaster, StaleTelegramLosesTheAxisAndItComesBackDisabled) {
  MasterSettings s;
  s.stale_timeout = 20ms;
  Harness h(9, s);
  h.enable_and_home();
  ASSERT_TRUE(h.submit(move(3, 50000)).accepted);
  h.run(5);
  h.drive.fresh = false;
  h.run(10);
  EXPECT_EQ(h.sink.replies(3), 0U);  // within the data-hold time: still going
  h.run(15);
  EXPECT_NE(h.sink.failure(3).find("not refreshed"), std::string::npos) << h.sink.failure(3);
  EXPECT_FALSE(h.master.feedback().valid);
  EXPECT_EQ(h.master.feedback().state, AxisState::Unknown);
  EXPECT_EQ(h.drive.stw1(), 0x0402);  // the drive (if it still listens) quick-stops
  EXPECT_FALSE(h.submit(command(4, CommandKind::Enable)).accepted);
  h.drive.fresh = true;
  h.run(30);
  EXPECT_TRUE(h.master.feedback().valid);
  EXPECT_EQ(h.drive.state, State::S1);
  EXPECT_EQ(h.master.feedback().state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.drive.stw1(), 0x0402);
}

TEST(ProfidriveMaster, InvalidTelegramLosesTheAxisAtOnce) {
  Harness h(1);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, kOneRps)).accepted);
  h.cycle();
  h.drive.valid = false;
  h.cycle();
  EXPECT_NE(h.sink.failure(2).find("invalid"), std::string::npos) << h.sink.failure(2);
  EXPECT_FALSE(h.master.feedback().valid);
}

TEST(ProfidriveMaster, WrongLengthTelegramsCountAsNone) {
  MasterSettings s;
  s.stale_timeout = 20ms;
  Harness h(1, s);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, kOneRps)).accepted);
  h.drive.short_actual = true;
  h.run(10);
  EXPECT_EQ(h.master.bad_telegrams(), 10U);
  EXPECT_EQ(h.sink.replies(2), 0U);
  h.run(20);
  EXPECT_NE(h.sink.failure(2).find("not refreshed"), std::string::npos) << h.sink.failure(2);
}

TEST(ProfidriveMaster, LinkLostFailsEverythingInFlightAndComesBackDisabled) {
  Harness h(9);
  h.enable_and_home();
  ASSERT_TRUE(h.submit(move(3, 50000)).accepted);
  core::ParamRequest r;
  r.id = 40;
  r.index = 1002;
  ASSERT_TRUE(h.param(r).accepted);
  h.run(1);
  h.master.link_lost(h.now, h.sink);
  EXPECT_EQ(h.sink.failure(3), "link to drive lost");
  ASSERT_EQ(h.sink.params.size(), 1U);
  EXPECT_FALSE(h.sink.params[0].ok);
  EXPECT_EQ(h.sink.params[0].error.view(), "link to drive lost");
  EXPECT_FALSE(h.master.feedback().valid);
  h.run(30);
  EXPECT_EQ(h.drive.state, State::S1);  // quick-stopped, nothing moves
  EXPECT_EQ(h.master.feedback().state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(h.sink.params.size(), 1U);
}

}  // namespace
}  // namespace drivegate::profidrive::test
