// ProfidriveMaster against the scripted drive: speed mode, MDI, program mode, homing, real-time
// jog, halt and stop, and the commands a telegram cannot carry.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "profiles/profidrive/scaling.hpp"
#include "tests/profidrive/master_harness.hpp"

namespace drivegate::profidrive::test {
namespace {

using core::Mode;
using State = ScriptedDrive::State;

std::string refusal(Harness& h, const core::DriveCommand& c) {
  const core::Admission a = h.submit(c);
  EXPECT_FALSE(a.accepted);
  return std::string(a.reason.view());
}

TEST(ProfidriveMasterSpeed, VelocityGoesToNsollAAndCompletesAtSpeedReached) {
  Harness h(350);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, kOneRps)).accepted);
  h.cycle();
  // 60 rpm: 163.84 -> 164 (§17.1 truncates to 163 = 0x00A3; the profile rounds to nearest).
  EXPECT_EQ(h.drive.sent().nsoll_a, 164);
  EXPECT_EQ(h.drive.sent().stw1, 0x047F);
  ASSERT_TRUE(h.wait(2));
  EXPECT_TRUE(h.sink.done(2));
  EXPECT_EQ(h.drive.speed, 164);
  EXPECT_EQ(h.master.feedback().velocity, native_from_nist(164));
  EXPECT_EQ(h.master.feedback().torque, -182);  // ITIST_GLATT in telegram 350
  EXPECT_EQ(h.master.feedback().mode, Mode::ProfileVelocity);
}

TEST(ProfidriveMasterSpeed, HaltTakesTheSetpointAwayAndResumeGivesItBack) {
  Harness h(1);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, kOneRps)).accepted);
  ASSERT_TRUE(h.wait(2));
  ASSERT_TRUE(h.submit(command(3, CommandKind::Halt)).accepted);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x043F);  // bit 6 low: set-point 0, ramp on
  ASSERT_TRUE(h.wait(3));
  EXPECT_TRUE(h.sink.done(3));
  EXPECT_EQ(h.drive.speed, 0);
  EXPECT_TRUE(h.master.feedback().halted);
  ASSERT_TRUE(h.submit(command(4, CommandKind::Resume)).accepted);
  EXPECT_TRUE(h.sink.done(4));
  h.run(20);
  EXPECT_EQ(h.drive.speed, 164);
}

TEST(ProfidriveMasterSpeed, StopRampsToZeroAndStaysEnabled) {
  Harness h(1);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, -kOneRps)).accepted);
  ASSERT_TRUE(h.wait(2));
  EXPECT_EQ(h.drive.speed, -164);
  ASSERT_TRUE(h.submit(command(3, CommandKind::Stop)).accepted);
  ASSERT_TRUE(h.wait(3));
  EXPECT_TRUE(h.sink.done(3));
  EXPECT_EQ(h.drive.speed, 0);
  EXPECT_EQ(h.drive.state, State::S4);
}

TEST(ProfidriveMasterSpeed, RefusesWhatTelegramOneCannotCarry) {
  Harness h(1);
  h.enable();
  EXPECT_NE(refusal(h, move(2, 100)).find("telegram 1 carries no MDI signals"), std::string::npos);
  EXPECT_NE(refusal(h, home(3)).find("telegram 1 carries no position mode"), std::string::npos);
  EXPECT_NE(refusal(h, run_block(4, 1)).find("telegram 1 carries no SATZANW"), std::string::npos);
  EXPECT_NE(refusal(h, command(5, CommandKind::Torque)).find("no torque"), std::string::npos);
  EXPECT_NE(refusal(h, command(6, CommandKind::SetMode, Mode::CyclicPosition)).find("no such mode"), std::string::npos);
  // 2^15 = 12000 rpm does not fit NSOLL_A.
  EXPECT_NE(refusal(h, velocity(7, 2147483647)).find("does not fit NSOLL_A"), std::string::npos);
  EXPECT_TRUE(h.sink.completed_ids.size() == 1);  // only the enable
}

TEST(ProfidriveMasterMdi, MoveNeedsHomingThenRunsTheEdgeHandshake) {
  Harness h(9);
  h.enable();
  EXPECT_NE(refusal(h, move(2, 5000)).find("not homed"), std::string::npos);
  ASSERT_TRUE(h.submit(home(3)).accepted);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x0C0F);  // bit 11 [§16.4]
  ASSERT_TRUE(h.wait(3));
  EXPECT_TRUE(h.sink.done(3));
  EXPECT_TRUE(h.master.feedback().homed);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x040F);  // bit 11 back to 0 once homed

  ASSERT_TRUE(h.submit(move(4, 5000)).accepted);
  h.cycle();
  const Setpoints primed = h.drive.sent();
  EXPECT_EQ(primed.stw1, 0x043F);  // bits 4, 5 with the values, bit 6 still low
  EXPECT_EQ(primed.satzanw, 0x8000);
  EXPECT_EQ(primed.mdi_tarpos, 5000);
  EXPECT_EQ(primed.mdi_velocity, static_cast<std::uint32_t>(kOneRps) * 2U);
  EXPECT_EQ(primed.mdi_acc, 100);
  EXPECT_EQ(primed.mdi_dec, 200);
  EXPECT_EQ(primed.mdi_mod, 1);  // absolute
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x047F);  // the edge
  ASSERT_TRUE(h.wait(4));
  EXPECT_TRUE(h.sink.done(4));
  EXPECT_EQ(h.drive.position, 5000);
  EXPECT_EQ(h.master.feedback().position, 5000);
  EXPECT_TRUE(h.master.feedback().target_reached);
  EXPECT_EQ(h.master.feedback().mode, Mode::ProfilePosition);

  // The next task: bit 6 drops, the acknowledge drops, then the new values and a new edge.
  ASSERT_TRUE(h.submit(move(5, -300, true)).accepted);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x043F);
  EXPECT_EQ(h.drive.sent().mdi_tarpos, 5000);  // old values until the acknowledge dropped
  ASSERT_TRUE(h.run_until([&] { return h.drive.sent().stw1 == 0x047F; }, 20));
  EXPECT_EQ(h.drive.sent().mdi_tarpos, -300);
  EXPECT_EQ(h.drive.sent().mdi_mod, 0);  // relative
  ASSERT_TRUE(h.wait(5));
  EXPECT_TRUE(h.sink.done(5));
  EXPECT_EQ(h.drive.position, 4700);
}

TEST(ProfidriveMasterMdi, UnacknowledgedTaskFailsInWords) {
  MasterSettings s;
  s.ack_timeout = 30ms;
  Harness h(9, s);
  h.enable_and_home();
  h.drive.refuse_tasks = true;
  ASSERT_TRUE(h.submit(move(3, 5000)).accepted);
  ASSERT_TRUE(h.wait(3, 100));
  EXPECT_NE(h.sink.failure(3).find("did not acknowledge the MDI task (ZSW1 bit 12)"), std::string::npos)
      << h.sink.failure(3);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x040F);  // task bits dropped
}

TEST(ProfidriveMasterMdi, NewerMoveSupersedesAndStopAbortsTheTask) {
  Harness h(9);
  h.enable_and_home();
  ASSERT_TRUE(h.submit(move(3, 100000)).accepted);
  h.run(5);
  ASSERT_TRUE(h.submit(move(4, 200000)).accepted);
  EXPECT_EQ(h.sink.failure(3), "superseded by a newer move command");
  h.run(5);
  ASSERT_TRUE(h.submit(command(5, CommandKind::Stop)).accepted);
  EXPECT_EQ(h.sink.failure(4), "aborted by a stop command");
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x040F);  // bit 4 low rejects the task
  ASSERT_TRUE(h.wait(5));
  EXPECT_TRUE(h.sink.done(5));
  EXPECT_FALSE(h.drive.moving);
  EXPECT_LT(h.drive.position, 200000);
}

TEST(ProfidriveMasterMdi, RefusesRampsTheWordsCannotHold) {
  Harness h(9);
  h.enable_and_home();
  core::DriveCommand c = move(3, 100);
  c.profile_acceleration = 0;
  EXPECT_NE(refusal(h, c).find("MDI_ACC"), std::string::npos);
  c = move(4, 100);
  c.profile_deceleration = 70000;
  EXPECT_NE(refusal(h, c).find("MDI_DEC"), std::string::npos);
  c = move(5, 100);
  c.profile_velocity = 0x80000000U;
  EXPECT_NE(refusal(h, c).find("MDI_VELOCITY"), std::string::npos);
}

TEST(ProfidriveMasterHoming, HomeModeAndDistanceGoOutWhereTheTelegramCarriesThem) {
  Harness h(353);
  h.enable();
  ASSERT_TRUE(h.submit(home(2, 7, 1234)).accepted);
  h.cycle();
  EXPECT_EQ(h.drive.sent().home_mode, 7);
  EXPECT_EQ(h.drive.sent().home_dist, 1234);
  ASSERT_TRUE(h.wait(2));
  EXPECT_TRUE(h.sink.done(2));
  EXPECT_EQ(h.drive.position, 1234);
  EXPECT_EQ(h.master.feedback().mode, Mode::Homing);

  Harness t9(9);
  t9.enable();
  EXPECT_NE(refusal(t9, home(2, 7)).find("telegram 9 carries no HOME_MODE"), std::string::npos);
  EXPECT_NE(refusal(t9, home(3, 0, 10)).find("telegram 9 carries no HOME_DIST"), std::string::npos);
}

TEST(ProfidriveMasterHoming, TimesOutAndAbortingLeavesTheAxisUnhomed) {
  MasterSettings s;
  s.homing_timeout = 20ms;
  Harness h(9, s);
  h.drive.home_cycles = 1000;
  h.enable();
  ASSERT_TRUE(h.submit(home(2)).accepted);
  ASSERT_TRUE(h.wait(2, 100));
  EXPECT_NE(h.sink.failure(2).find("homing did not finish within 20 ms"), std::string::npos) << h.sink.failure(2);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1 & 0x0800, 0);  // bit 11 dropped: aborted
  h.run(3);
  EXPECT_FALSE(h.drive.homed);
  EXPECT_FALSE(h.master.feedback().homed);
}

TEST(ProfidriveMasterProgram, RunBlockSelectsTheBlockAndWaitsForIt) {
  Harness h(7);
  h.enable();
  EXPECT_NE(refusal(h, move(2, 100)).find("telegram 7 carries no MDI signals"), std::string::npos);
  EXPECT_NE(refusal(h, velocity(3, kOneRps)).find("telegram 7 carries no speed set-point"), std::string::npos);
  EXPECT_NE(refusal(h, run_block(4, 2)).find("not homed"), std::string::npos);
  ASSERT_TRUE(h.submit(home(5)).accepted);
  ASSERT_TRUE(h.wait(5));
  EXPECT_NE(refusal(h, run_block(6, 0x8000)).find("SATZANW takes 0 .. 32767"), std::string::npos);

  ASSERT_TRUE(h.submit(run_block(7, 2)).accepted);
  h.cycle();
  EXPECT_EQ(h.drive.sent().satzanw, 2);
  EXPECT_EQ(h.drive.sent().stw1, 0x043F);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x047F);
  h.run(5);
  EXPECT_EQ(h.sink.replies(7), 0U);
  // Intermediate stop: bit 5 low holds the task, bit 5 high resumes it [§16.2].
  ASSERT_TRUE(h.submit(command(8, CommandKind::Halt)).accepted);
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x045F);
  const std::int32_t held = h.drive.position;
  h.run(5);
  EXPECT_EQ(h.drive.position, held);
  EXPECT_TRUE(h.sink.done(8));  // standing (ZSW1 bit 13) in the intermediate stop
  EXPECT_EQ(h.sink.replies(7), 0U);
  ASSERT_TRUE(h.submit(command(9, CommandKind::Resume)).accepted);
  ASSERT_TRUE(h.wait(7));
  EXPECT_TRUE(h.sink.done(7));
  EXPECT_EQ(h.drive.position, 3000);
  EXPECT_EQ(h.drive.aktsatz, 2);
  EXPECT_EQ(h.master.feedback().mode, Mode::TraversingBlock);
}

TEST(ProfidriveMasterProgram, UnknownBlockIsNotAcknowledged) {
  MasterSettings s;
  s.ack_timeout = 30ms;
  Harness h(7, s);
  h.enable_and_home();
  ASSERT_TRUE(h.submit(run_block(3, 9)).accepted);
  ASSERT_TRUE(h.wait(3, 100));
  EXPECT_NE(h.sink.failure(3).find("did not acknowledge the traversing block"), std::string::npos)
      << h.sink.failure(3);
}

TEST(ProfidriveMasterProgram, AktsatzWithTaskActiveAlsoAcknowledges) {
  MasterSettings s;
  s.ack_timeout = 30ms;
  Harness h(7, s);
  h.drive.program_without_ack = true;
  h.drive.move_step = 10;  // long enough for bit 14 to show
  h.enable_and_home();
  ASSERT_TRUE(h.submit(run_block(3, 1)).accepted);
  ASSERT_TRUE(h.wait(3, 1000));
  EXPECT_TRUE(h.sink.done(3)) << h.sink.failure(3);
  EXPECT_EQ(h.drive.position, 2000);
}

TEST(ProfidriveMasterJog, VelocityOnAnMdiTelegramIsRealTimeJog) {
  Harness h(9);
  h.enable();
  ASSERT_TRUE(h.submit(velocity(2, -kOneRps)).accepted);
  h.cycle();
  // Bit 12 jog, bit 13 counter-clockwise, MDI_VELOCITY = |v| x 2 [§16.5].
  EXPECT_EQ(h.drive.sent().stw1, 0x340F);
  EXPECT_EQ(h.drive.sent().mdi_velocity, static_cast<std::uint32_t>(kOneRps) * 2U);
  ASSERT_TRUE(h.wait(2));
  EXPECT_TRUE(h.sink.done(2));
  h.run(10);
  EXPECT_LT(h.drive.position, 0);
  // Telegram 9 carries no NIST_A: the velocity is XIST_A's slope, 10 counts per 1 ms telegram at
  // 65536 counts per rev (MasterSettings' default) in the native unit.
  EXPECT_NEAR(h.master.feedback().velocity, -10 * 1000 * h.settings.velocity_per_count, 1.0);
  ASSERT_TRUE(h.submit(velocity(3, 0)).accepted);  // 0 is a stop
  h.cycle();
  EXPECT_EQ(h.drive.sent().stw1, 0x040F);
  ASSERT_TRUE(h.wait(3));
  EXPECT_TRUE(h.sink.done(3));
  const std::int32_t at = h.drive.position;
  h.run(10);
  EXPECT_EQ(h.drive.position, at);
  EXPECT_EQ(h.master.feedback().velocity, 0);
}

TEST(ProfidriveMaster, CapabilitiesFollowTheTelegram) {
  const auto caps = [](std::uint16_t t) { return capabilities_of(*standard_layout(t)); };
  EXPECT_TRUE(caps(1).speed);
  EXPECT_FALSE(caps(1).position);
  EXPECT_TRUE(caps(351).position_actual);
  EXPECT_TRUE(caps(7).position);
  EXPECT_FALSE(caps(7).mdi);
  EXPECT_TRUE(caps(9).mdi);
  EXPECT_FALSE(caps(9).home_dist);
  EXPECT_TRUE(caps(352).home_dist);
  EXPECT_FALSE(caps(352).home_mode);
  EXPECT_TRUE(caps(353).home_mode);
  // A free layout with NSOLL_A and SATZANW is taken as position mode.
  const std::uint16_t out[] = {1, 5, 32};
  const std::uint16_t in[] = {2, 6, 33};
  const LayoutResult both = free_layout(400, out, 12, in, 12);
  ASSERT_EQ(both.error, TelegramError::None);
  EXPECT_TRUE(capabilities_of(both.layout).position);
  EXPECT_FALSE(capabilities_of(both.layout).speed);
}

TEST(ProfidriveMaster, SetModeIsRememberedAndStreamingSetpointsAreDropped) {
  Harness h(9);
  h.enable();
  ASSERT_TRUE(h.submit(command(2, CommandKind::SetMode, Mode::Homing)).accepted);
  EXPECT_TRUE(h.sink.done(2));
  h.cycle();
  EXPECT_EQ(h.master.feedback().mode, Mode::Homing);
  EXPECT_EQ(h.sink.count(core::EventKind::ModeChanged), 2U);  // none -> pp, pp -> hm
  h.master.setpoint(core::DriveSetpoint{}, h.now);
  EXPECT_EQ(h.master.dropped_setpoints(), 1U);
  EXPECT_EQ(h.drive.state, State::S4);
}

}  // namespace
}  // namespace drivegate::profidrive::test
