#include "core/axis_runner.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/bus_runner.hpp"
#include "tests/core/test_spec.hpp"
#include "tests/support/alloc_counter.hpp"

using namespace drivegate::core;
using namespace std::chrono_literals;

namespace {

// A controller that records what it is asked and completes commands when told to.
class FakeController final : public AxisController {
 public:
  FakeController() { submitted.reserve(64); }  // the fake must not allocate in the cycle either
  Admission submit(const DriveCommand& cmd, TimePoint, ControllerSink& sink) noexcept override {
    submitted.push_back(cmd);
    if (refuse) return Admission::reject("axis is in fault: send fault_reset first");
    // Like the CiA 402 master: a new command aborts the one in flight.
    if (abort_in_flight && in_flight != 0) sink.failed(in_flight, "aborted by a newer command");
    in_flight = cmd.id;
    if (complete_inline) sink.completed(cmd.id);
    if (cmd.kind == CommandKind::Velocity && mode_follows) fb.mode = Mode::ProfileVelocity;
    return Admission::accept();
  }
  void setpoint(const DriveSetpoint& sp, TimePoint) noexcept override { last_setpoint = sp; ++setpoints; }
  Admission parameter(const ParamRequest&, TimePoint) noexcept override { return Admission::reject("no"); }
  void update(TimePoint, ControllerSink& sink) noexcept override {
    if (complete_next != 0) {
      sink.completed(complete_next);
      complete_next = 0;
    }
  }
  void link_lost(TimePoint, ControllerSink&) noexcept override { ++link_losses; }
  const DriveFeedback& feedback() const noexcept override { return fb; }

  DriveFeedback fb;
  std::vector<DriveCommand> submitted;
  DriveSetpoint last_setpoint;
  int setpoints = 0;
  int link_losses = 0;
  bool refuse = false;
  bool complete_inline = false;
  bool abort_in_flight = false;
  bool mode_follows = true;  // false: the drive still shows its old mode (6061h lags behind 6060h)
  CommandId in_flight = 0;
  CommandId complete_next = 0;
};

class Recorder final : public RunnerOutput {
 public:
  void reply(const Reply& r) noexcept override { replies.push_back(r); }
  void event(const Event& e) noexcept override { events.push_back(e); }
  void parameter_reply(const ParamReply& r) noexcept override { params.push_back(r); }
  std::vector<Reply> replies;
  std::vector<Event> events;
  std::vector<ParamReply> params;
  // The replies to one command, in order.
  std::vector<Reply> to(CommandId id) const {
    std::vector<Reply> v;
    for (const auto& r : replies)
      if (r.id == id) v.push_back(r);
    return v;
  }
  bool has_event(EventKind k) const {
    for (const auto& e : events)
      if (e.kind == k) return true;
    return false;
  }
  std::string events_text() const {
    std::string s;
    for (const auto& e : events) s += std::string(to_string(e.kind)) + ": " + std::string(e.text.view()) + "\n";
    return s;
  }
};

struct RunnerFixture : ::testing::Test {
  RunnerFixture() {
    ctl.fb.valid = true;
    ctl.fb.state = AxisState::OperationEnabled;
    runner.update(now, LinkState::Operational, out);
  }
  AxisSpec spec = drivegate::test::linear_axis_spec();
  FakeController ctl;
  AxisRunner runner{0, spec, ctl};
  Recorder out;
  TimePoint now{1s};
};

Command cmd(CommandId id, CommandKind kind) {
  Command c;
  c.id = id;
  c.axis = 0;
  c.kind = kind;
  return c;
}

}  // namespace

TEST_F(RunnerFixture, AcceptedThenCompletedExactlyOnce) {
  auto c = cmd(5, CommandKind::Move);
  c.position = 10;
  runner.command(c, now, out);
  ASSERT_EQ(out.replies.size(), 1u);
  EXPECT_EQ(out.replies[0].status, ReplyStatus::Accepted);
  EXPECT_EQ(ctl.submitted.back().target_position, 10000);
  EXPECT_EQ(runner.snapshot().active_command, 0u);  // snapshot is built on update
  ctl.complete_next = 5;
  runner.update(now + 1ms, LinkState::Operational, out);
  ASSERT_EQ(out.replies.size(), 2u);
  EXPECT_EQ(out.replies[1].status, ReplyStatus::Completed);
  EXPECT_EQ(out.replies[1].id, 5u);
}

TEST_F(RunnerFixture, InlineCompletionStillRepliesAcceptedFirst) {
  ctl.complete_inline = true;
  runner.command(cmd(9, CommandKind::Resume), now, out);
  ASSERT_EQ(out.replies.size(), 2u);
  EXPECT_EQ(out.replies[0].status, ReplyStatus::Accepted);
  EXPECT_EQ(out.replies[1].status, ReplyStatus::Completed);
}

TEST_F(RunnerFixture, ControllerRefusalBecomesRejectedWithItsReason) {
  ctl.refuse = true;
  runner.command(cmd(3, CommandKind::Enable), now, out);
  ASSERT_EQ(out.replies.size(), 1u);
  EXPECT_EQ(out.replies[0].status, ReplyStatus::Rejected);
  EXPECT_EQ(out.replies[0].reason.view(), "axis is in fault: send fault_reset first");
}

// The snapshot says why the link is in its state and since when: the detail follows the bus
// (also while the state stays), the time only changes with the state.
TEST_F(RunnerFixture, SnapshotCarriesTheLinkDetailAndSinceWhen) {
  EXPECT_EQ(runner.snapshot().link_since_ns, to_ns(now));
  const TimePoint lost = now + 10ms;
  runner.observe_link(lost, LinkState::Lost, "node 35 stopped answering (heartbeat timeout)", out);
  runner.update(lost, out);
  EXPECT_EQ(runner.snapshot().link, LinkState::Lost);
  EXPECT_EQ(runner.snapshot().link_detail.view(), "node 35 stopped answering (heartbeat timeout)");
  EXPECT_EQ(runner.snapshot().link_since_ns, to_ns(lost));
  const TimePoint later = lost + 500ms;
  runner.observe_link(later, LinkState::Lost, "node 35: asking it again after 500 ms (SDO read of 1000h)", out);
  runner.update(later, out);
  EXPECT_EQ(runner.snapshot().link_detail.view(), "node 35: asking it again after 500 ms (SDO read of 1000h)");
  EXPECT_EQ(runner.snapshot().link_since_ns, to_ns(lost));
}

TEST_F(RunnerFixture, CommandsAreRejectedWhileTheLinkIsDown) {
  runner.update(now, LinkState::Lost, out);
  EXPECT_EQ(ctl.link_losses, 1);
  EXPECT_TRUE(out.has_event(EventKind::LinkChanged));
  runner.command(cmd(4, CommandKind::Enable), now, out);
  ASSERT_EQ(out.replies.size(), 1u);
  EXPECT_EQ(out.replies[0].status, ReplyStatus::Rejected);
  EXPECT_NE(out.replies[0].reason.view().find("link is lost"), std::string_view::npos);
  EXPECT_TRUE(ctl.submitted.empty());
}

TEST_F(RunnerFixture, SilenceAfterVelocityCommandStopsTheAxis) {
  auto v = cmd(11, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  ASSERT_EQ(ctl.submitted.size(), 1u);
  // Set-points keep it alive.
  for (int i = 1; i <= 5; ++i) {
    Setpoint sp;
    sp.axis = 0;
    sp.velocity = 20;
    runner.setpoint(sp, now + i * 50ms, out);
    runner.update(now + i * 50ms, LinkState::Operational, out);
  }
  EXPECT_EQ(ctl.submitted.size(), 1u);
  EXPECT_EQ(ctl.setpoints, 0);  // in pv a set-point is a keep-alive; the command set the target
  // Then silence: after 100 ms the runner issues a quick stop of its own, without a reply.
  runner.update(now + 250ms + 90ms, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 1u);
  runner.update(now + 250ms + 101ms, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.size(), 2u);
  EXPECT_EQ(ctl.submitted[1].kind, CommandKind::QuickStop);
  EXPECT_TRUE(is_internal(ctl.submitted[1].id));
  EXPECT_TRUE(out.has_event(EventKind::CommandTimeout));
  // Only once.
  runner.update(now + 2s, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 2u);
}

// A velocity command's final reply comes when the run ends, not when the speed is reached: here
// the command timeout ends it, so it fails with the timeout as its reason.
TEST_F(RunnerFixture, VelocityStoppedByTheCommandTimeoutFailsWithTheTimeout) {
  auto v = cmd(31, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  ctl.complete_next = 31;  // the drive reached the speed
  runner.update(now + 10ms, LinkState::Operational, out);
  ASSERT_EQ(out.to(31).size(), 1u);
  EXPECT_EQ(out.to(31)[0].status, ReplyStatus::Accepted);
  EXPECT_EQ(runner.snapshot().active_command, 31u);  // still running
  runner.update(now + 200ms, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.back().kind, CommandKind::QuickStop);
  const auto r = out.to(31);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[1].status, ReplyStatus::Failed);
  EXPECT_NE(r[1].reason.view().find("command timeout 100 ms"), std::string_view::npos) << r[1].reason.view();
  runner.update(now + 1s, LinkState::Operational, out);
  EXPECT_EQ(out.to(31).size(), 2u);  // exactly one final reply
}

// The same while the drive is still accelerating: the controller aborts the command for the
// gateway's stop, and the reply names the timeout instead of the internal stop command.
TEST_F(RunnerFixture, VelocityAbortedByTheTimeoutBeforeReachingSpeedFailsWithTheTimeout) {
  ctl.abort_in_flight = true;
  auto v = cmd(32, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  runner.update(now + 200ms, LinkState::Operational, out);
  const auto r = out.to(32);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[1].status, ReplyStatus::Failed);
  EXPECT_NE(r[1].reason.view().find("no command or set-point"), std::string_view::npos) << r[1].reason.view();
  EXPECT_EQ(r[1].reason.view().find("command 9"), std::string_view::npos) << r[1].reason.view();
}

// A client's stop (or any later motion command) ends the run as asked: completed.
TEST_F(RunnerFixture, VelocityEndedByTheClientsStopCompletes) {
  auto v = cmd(33, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  ctl.complete_next = 33;
  runner.update(now + 10ms, LinkState::Operational, out);
  runner.command(cmd(34, CommandKind::Halt), now + 20ms, out);  // a pause does not end it
  EXPECT_EQ(out.to(33).size(), 1u);
  runner.command(cmd(35, CommandKind::Stop), now + 30ms, out);
  auto r = out.to(33);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[1].status, ReplyStatus::Completed);
  // Not yet at speed, replaced by a new velocity command: completed too.
  ctl.abort_in_flight = true;
  auto w = cmd(36, CommandKind::Velocity);
  w.velocity = 10;
  runner.command(w, now + 40ms, out);
  auto w2 = cmd(37, CommandKind::Velocity);
  w2.velocity = 15;
  runner.command(w2, now + 50ms, out);
  r = out.to(36);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[1].status, ReplyStatus::Completed);
}

// A drive that leaves operation enabled by itself (fault) or a lost link ends the run: failed.
TEST_F(RunnerFixture, VelocityEndedByAFaultOrLinkLossFails) {
  auto t = cmd(38, CommandKind::Torque);
  t.torque = 10;
  runner.command(t, now, out);
  ctl.complete_next = 38;
  runner.update(now + 10ms, LinkState::Operational, out);
  ctl.fb.state = AxisState::Fault;
  ctl.fb.fault_text.assign("F501 bus overvoltage");
  runner.update(now + 20ms, LinkState::Operational, out);
  auto r = out.to(38);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[1].status, ReplyStatus::Failed);
  EXPECT_NE(r[1].reason.view().find("F501"), std::string_view::npos) << r[1].reason.view();

  ctl.fb.state = AxisState::OperationEnabled;
  auto v = cmd(39, CommandKind::Velocity);
  v.velocity = 5;
  runner.command(v, now + 30ms, out);
  ctl.complete_next = 39;
  runner.update(now + 40ms, LinkState::Operational, out);
  runner.update(now + 50ms, LinkState::Lost, out);
  r = out.to(39);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[1].status, ReplyStatus::Failed);
  EXPECT_EQ(r[1].reason.view(), "link to drive lost");
}

TEST_F(RunnerFixture, HaltAndResumeKeepTheCommandTimeoutArmed) {
  auto v = cmd(14, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  runner.command(cmd(15, CommandKind::Halt), now + 10ms, out);
  runner.command(cmd(16, CommandKind::Resume), now + 20ms, out);
  runner.update(now + 200ms, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.size(), 4u);
  EXPECT_EQ(ctl.submitted[3].kind, CommandKind::QuickStop);
}

TEST_F(RunnerFixture, SetModeToTheRunningModeKeepsTheCommandTimeoutArmed) {
  auto v = cmd(17, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  auto m = cmd(18, CommandKind::SetMode);
  m.mode = Mode::ProfileVelocity;
  runner.command(m, now + 10ms, out);
  runner.update(now + 200ms, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.size(), 3u);
  EXPECT_EQ(ctl.submitted[2].kind, CommandKind::QuickStop);
}

TEST_F(RunnerFixture, RelativeMovesBecomeAbsoluteAndAreCheckedAtTheirEnd) {
  // Axis at 0; a move to 450 is in flight: a relative +40 ends at 490 (allowed), +60 at 510 (not).
  auto a = cmd(20, CommandKind::Move);
  a.position = 450;
  runner.command(a, now, out);
  auto r = cmd(21, CommandKind::Move);
  r.relative = true;
  r.position = 60;
  runner.command(r, now, out);
  EXPECT_EQ(out.replies.back().status, ReplyStatus::Rejected);
  r.id = 22;
  r.position = 40;
  runner.command(r, now, out);
  EXPECT_EQ(out.replies.back().status, ReplyStatus::Accepted);
  EXPECT_EQ(ctl.submitted.back().target_position, 490000);
  EXPECT_FALSE(ctl.submitted.back().relative);
  // Once that move is done, relative moves count from the actual position.
  ctl.complete_next = 22;
  ctl.fb.position = 490000;
  runner.update(now + 1ms, LinkState::Operational, out);
  r.id = 23;
  r.position = -10;
  runner.command(r, now + 2ms, out);
  EXPECT_EQ(ctl.submitted.back().target_position, 480000);
}

TEST_F(RunnerFixture, LeavingTheSoftLimitsInVelocityModeQuickStops) {
  auto v = cmd(24, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  ctl.fb.velocity = 20000;
  ctl.fb.position = 499000;  // 499 mm, inside
  runner.update(now + 1ms, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 1u);
  ctl.fb.position = 500500;  // 500.5 mm, outside and moving out
  runner.update(now + 2ms, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.size(), 2u);
  EXPECT_EQ(ctl.submitted[1].kind, CommandKind::QuickStop);
  runner.update(now + 3ms, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 2u);  // once per excursion
  // Moving back in is allowed.
  ctl.fb.velocity = -20000;
  runner.update(now + 4ms, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 2u);
}

TEST_F(RunnerFixture, PositionModesHaveNoCommandTimeout) {
  auto m = cmd(12, CommandKind::Move);
  m.position = 100;
  runner.command(m, now, out);
  runner.update(now + 10s, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 1u);
}

TEST_F(RunnerFixture, HaltIsUsedWhenConfigured) {
  spec.timeout_stop = TimeoutStop::Halt;
  auto v = cmd(13, CommandKind::Velocity);
  v.velocity = 5;
  runner.command(v, now, out);
  runner.update(now + 1s, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.size(), 2u);
  EXPECT_EQ(ctl.submitted[1].kind, CommandKind::Stop);
}

TEST_F(RunnerFixture, SnapshotIsInUserUnits) {
  ctl.fb.position = 12345;
  ctl.fb.velocity = -2000;
  ctl.fb.torque = 250;
  runner.update(now, LinkState::Operational, out);
  EXPECT_DOUBLE_EQ(runner.snapshot().position, 12.345);
  EXPECT_DOUBLE_EQ(runner.snapshot().velocity, -2.0);
  EXPECT_DOUBLE_EQ(runner.snapshot().torque, 25.0);
  EXPECT_EQ(runner.snapshot().state, AxisState::OperationEnabled);
}

namespace {
class FakeBus final : public Bus {
 public:
  std::string_view name() const noexcept override { return "fake"; }
  std::string_view type() const noexcept override { return "fake"; }
  void open(TimePoint) override {}
  void close() noexcept override {}
  std::size_t axis_count() const noexcept override { return 2; }
  AxisController& controller(std::size_t i) noexcept override { return ctl[i]; }
  LinkState link_state(std::size_t i) const noexcept override { return link[i]; }
  std::string_view link_detail(std::size_t i) const noexcept override { return detail[i]; }
  void receive(TimePoint) noexcept override { ++receives; }
  void transmit(TimePoint) noexcept override { ++transmits; }
  // `pending_emcys` EMCY events: the first for axis 1, the others for an axis the bus does not have.
  bool next_event(Event& out) noexcept override {
    if (pending_emcys == 0) return false;
    out = Event{};
    out.kind = EventKind::Emcy;
    out.axis = pending_emcys == 2 ? 1 : 7;
    out.code = 0x3280;
    --pending_emcys;
    return true;
  }
  BusCounters counters() const noexcept override { return {}; }
  FakeController ctl[2];
  LinkState link[2] = {LinkState::Operational, LinkState::Operational};
  std::string detail[2];
  int receives = 0;
  int transmits = 0;
  int pending_emcys = 0;
};

// Specs of the bus' two axes (linear, "x" and "y"); its drives report switch on disabled.
std::vector<AxisSpec> two_axes(FakeBus& bus) {
  for (auto& c : bus.ctl) {
    c.fb.valid = true;
    c.fb.state = AxisState::SwitchOnDisabled;
  }
  std::vector<AxisSpec> specs{drivegate::test::linear_axis_spec(), drivegate::test::linear_axis_spec()};
  specs[1].name = "y";
  return specs;
}
}  // namespace

TEST(BusRunner, RoutesCommandsAndRepliesAndNeverAllocatesInTheCycle) {
  FakeBus bus;
  const std::vector<AxisSpec> specs = two_axes(bus);  // the runner keeps references to them
  BusRunner runner(bus, specs);
  TimePoint t{1s};
  runner.cycle(t);  // link up

  Command c = cmd(21, CommandKind::Enable);
  c.axis = 1;
  ASSERT_TRUE(runner.push_command(c));
  Command bad = cmd(22, CommandKind::Move);
  bad.axis = 0;
  bad.position = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(runner.push_command(bad));
  Setpoint sp;
  sp.axis = 0;
  ASSERT_TRUE(runner.push_setpoint(sp));

  std::size_t allocations = 0;
  {
    drivegate::test::AllocationScope scope;
    for (int i = 0; i < 1000; ++i) {
      t += 1ms;
      runner.cycle(t);
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(bus.receives, 1001);
  EXPECT_EQ(bus.transmits, 1001);
  ASSERT_EQ(bus.ctl[1].submitted.size(), 1u);
  EXPECT_EQ(bus.ctl[1].submitted[0].kind, CommandKind::Enable);
  EXPECT_TRUE(bus.ctl[0].submitted.empty());

  std::vector<Reply> replies;
  Reply r;
  while (runner.pop_reply(r)) replies.push_back(r);
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[0].id, 21u);
  EXPECT_EQ(replies[0].axis, 1);
  EXPECT_EQ(replies[0].status, ReplyStatus::Accepted);
  EXPECT_EQ(replies[1].id, 22u);
  EXPECT_EQ(replies[1].status, ReplyStatus::Rejected);
  EXPECT_EQ(runner.snapshot(1).cycle, 1001u);
  Event e;
  bool saw_link = false;
  while (runner.pop_event(e)) saw_link = saw_link || e.kind == EventKind::LinkChanged;
  EXPECT_TRUE(saw_link);
}

// A record request (PROFINET's rec:...) goes to the bus, not to the axis' controller; a bus
// without records refuses it in words, and one for an axis the bus lacks is the bus' to judge too.
TEST(BusRunner, RecordsGoToTheBusWhichRefusesThemWithoutRecords) {
  FakeBus bus;
  std::vector<AxisSpec> specs{drivegate::test::linear_axis_spec(), drivegate::test::linear_axis_spec()};
  specs[1].name = "y";
  BusRunner runner(bus, specs);
  ParamRequest q;
  q.id = 31;
  q.axis = 0;
  q.record.valid = true;
  q.record.index = 0xAFF0;
  ASSERT_TRUE(runner.push_parameter(q));
  q.id = 32;
  q.axis = kNoAxis;
  q.record.io = 3;
  ASSERT_TRUE(runner.push_parameter(q));
  runner.cycle(TimePoint{1s});
  ParamReply r;
  for (const CommandId id : {31U, 32U}) {
    ASSERT_TRUE(runner.pop_parameter_reply(r));
    EXPECT_EQ(r.id, id);
    EXPECT_FALSE(r.ok);
    EXPECT_EQ(r.error.view(), "this bus has no records (rec:SLOT:SUBSLOT:INDEX is PROFINET's record access)");
  }
  EXPECT_FALSE(runner.pop_parameter_reply(r));
}

TEST(AxisRunnerDefaultMode, SelectedOnceTheDriveReportsAndAgainAfterALinkLoss) {
  AxisSpec spec = drivegate::test::linear_axis_spec();
  spec.default_mode = Mode::ProfilePosition;
  FakeController ctl;
  AxisRunner runner{0, spec, ctl};
  Recorder out;
  TimePoint t{1s};
  runner.update(t, LinkState::Operational, out);  // no valid status yet: nothing sent
  EXPECT_TRUE(ctl.submitted.empty());
  ctl.fb.valid = true;
  ctl.fb.state = AxisState::SwitchOnDisabled;
  runner.update(t + 1ms, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.size(), 1u);
  EXPECT_EQ(ctl.submitted[0].kind, CommandKind::SetMode);
  EXPECT_EQ(ctl.submitted[0].mode, Mode::ProfilePosition);
  EXPECT_TRUE(is_internal(ctl.submitted[0].id));
  EXPECT_TRUE(out.replies.empty());  // the gateway's own command gets no reply
  runner.update(t + 2ms, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 1u);
  // After the link comes back the mode is selected again, unless the drive already has it.
  runner.update(t + 3ms, LinkState::Lost, out);
  runner.update(t + 4ms, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 2u);
  ctl.fb.mode = Mode::ProfilePosition;
  runner.update(t + 5ms, LinkState::Lost, out);
  runner.update(t + 6ms, LinkState::Operational, out);
  EXPECT_EQ(ctl.submitted.size(), 2u);
}

TEST_F(RunnerFixture, TimeoutArmedWhileTheDriveStillSwitchesIntoTheLiveMode) {
  ctl.fb.mode = Mode::ProfilePosition;
  auto v = cmd(30, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  ctl.fb.mode = Mode::ProfilePosition;  // 6061h has not followed yet
  runner.update(now + 1ms, LinkState::Operational, out);
  ctl.fb.mode = Mode::ProfileVelocity;
  runner.update(now + 200ms, LinkState::Operational, out);
  ASSERT_EQ(ctl.submitted.size(), 2u);
  EXPECT_EQ(ctl.submitted[1].kind, CommandKind::QuickStop);
}

// A velocity or torque command from profile position: while the drive still shows pp, the
// client's keep-alive set-points belong to the mode being entered. They keep the command alive
// (no command timeout) and are not refused with "profile_position takes no set-points".
TEST_F(RunnerFixture, KeepAlivesWhileSwitchingFromProfilePositionAreAcceptedSilently) {
  for (const CommandKind kind : {CommandKind::Velocity, CommandKind::Torque}) {
    SCOPED_TRACE(std::string(to_string(kind)));
    ctl.fb.mode = Mode::ProfilePosition;
    ctl.mode_follows = false;
    auto c = cmd(kind == CommandKind::Velocity ? 40 : 41, kind);
    c.velocity = 20;
    c.torque = 10;
    runner.command(c, now, out);
    ASSERT_EQ(out.to(c.id).size(), 1u);
    ASSERT_EQ(out.to(c.id)[0].status, ReplyStatus::Accepted) << out.to(c.id)[0].reason.view();
    const std::size_t submitted = ctl.submitted.size();
    // The switch takes longer than the command timeout (100 ms); the keep-alives hold it off.
    for (int i = 1; i <= 8; ++i) {
      Setpoint sp;
      sp.axis = 0;
      sp.velocity = 20;
      sp.torque = 10;
      runner.setpoint(sp, now + i * 50ms, out);
      runner.update(now + i * 50ms, LinkState::Operational, out);
    }
    EXPECT_EQ(ctl.submitted.size(), submitted) << "no stop of the gateway's own";
    EXPECT_FALSE(out.has_event(EventKind::CommandTimeout)) << out.events_text();
    EXPECT_FALSE(out.has_event(EventKind::Warning)) << out.events_text();
    EXPECT_EQ(runner.rejected_setpoints(), 0u);
    EXPECT_EQ(ctl.setpoints, 0);  // a keep-alive: the command set the target
    // The drive arrives in the mode: the keep-alives go on as before.
    ctl.fb.mode = kind == CommandKind::Velocity ? Mode::ProfileVelocity : Mode::ProfileTorque;
    ctl.complete_next = c.id;
    runner.update(now + 450ms, LinkState::Operational, out);
    Setpoint sp;
    sp.axis = 0;
    runner.setpoint(sp, now + 480ms, out);
    runner.update(now + 500ms, LinkState::Operational, out);
    EXPECT_FALSE(out.has_event(EventKind::Warning)) << out.events_text();
    EXPECT_EQ(ctl.submitted.size(), submitted);
    // The client stops; the next command starts from pp again.
    runner.command(cmd(c.id + 100, CommandKind::Stop), now + 500ms, out);
    now += 1s;
    runner.update(now, LinkState::Operational, out);
    out.events.clear();
  }
}

// Set-points for an axis whose mode (and the mode it is commanded into) takes none still warn:
// in pp without a command, and after a velocity command that a move superseded.
TEST_F(RunnerFixture, SetpointsForAModeThatTakesNoneWarn) {
  ctl.fb.mode = Mode::ProfilePosition;
  ctl.mode_follows = false;
  Setpoint sp;
  sp.axis = 0;
  runner.setpoint(sp, now, out);
  ASSERT_TRUE(out.has_event(EventKind::Warning));
  EXPECT_NE(out.events.back().text.view().find("profile_position, which takes no set-points"), std::string_view::npos)
      << out.events_text();
  EXPECT_EQ(runner.rejected_setpoints(), 1u);

  ctl.abort_in_flight = true;
  auto v = cmd(50, CommandKind::Velocity);
  v.velocity = 20;
  runner.command(v, now, out);
  runner.setpoint(sp, now + 1ms, out);
  EXPECT_EQ(runner.rejected_setpoints(), 1u);  // entering pv: a keep-alive
  auto m = cmd(51, CommandKind::Move);
  m.position = 5;
  runner.command(m, now + 2ms, out);  // aborts the velocity command: the axis stays in pp
  runner.setpoint(sp, now + 3ms, out);
  EXPECT_EQ(runner.rejected_setpoints(), 2u);
}

// Events a bus reports about one of its axes (a CANopen EMCY) keep their axis and get its state;
// the others are about the bus.
TEST(BusRunner, BusEventsKeepTheirAxis) {
  FakeBus bus;
  const std::vector<AxisSpec> specs = two_axes(bus);  // the runner keeps references to them
  BusRunner runner(bus, specs);
  runner.cycle(TimePoint{1s});
  Event e;
  while (runner.pop_event(e)) {
  }
  bus.pending_emcys = 2;
  runner.cycle(TimePoint{1s + 1ms});
  std::vector<Event> emcy;
  while (runner.pop_event(e))
    if (e.kind == EventKind::Emcy) emcy.push_back(e);
  ASSERT_EQ(emcy.size(), 2u);
  EXPECT_EQ(emcy[0].axis, 1);
  EXPECT_EQ(emcy[0].state, AxisState::SwitchOnDisabled);
  EXPECT_EQ(emcy[0].stamp_ns, to_ns(TimePoint{1s + 1ms}));
  EXPECT_EQ(emcy[1].axis, kNoAxis);  // no such axis: about the bus
}

// With a publish period the snapshots are stored at most that often (the daemon's readers sample
// them at the DDS status rate), and the first cycle's always.
TEST(BusRunner, SnapshotsAreStoredOncePerPublishPeriod) {
  FakeBus bus;
  const std::vector<AxisSpec> specs = two_axes(bus);  // the runner keeps references to them
  BusRunner runner(bus, specs);
  runner.set_publish_period(5ms);
  TimePoint t{1s};
  runner.cycle(t);
  EXPECT_EQ(runner.snapshot(1).cycle, 1u);
  for (int i = 0; i < 4; ++i) {
    t += 1ms;
    runner.cycle(t);
    EXPECT_EQ(runner.snapshot(0).cycle, 1u);
  }
  bus.ctl[1].fb.position = 1000;
  t += 1ms;
  runner.cycle(t);
  EXPECT_EQ(runner.snapshot(0).cycle, 6u);
  EXPECT_EQ(runner.snapshot(1).position, drivegate::test::linear_axis_spec().units.position_to_user(1000));
}

// Between publishes the runner skips the snapshot and the link detail text, not the link: a link
// change is an event (and the end of the axis' commands) in the cycle it happens, with the detail
// of that moment, and a detail that changes while the link stays shows in the next snapshot.
TEST(BusRunner, LinkChangesAreSeenEveryCycleAndTheDetailInTheNextSnapshot) {
  FakeBus bus;
  const std::vector<AxisSpec> specs = two_axes(bus);  // the runner keeps references to them
  BusRunner runner(bus, specs);
  runner.set_publish_period(5ms);
  TimePoint t{1s};
  runner.cycle(t);  // publishes
  Event e;
  while (runner.pop_event(e)) {
  }
  t += 1ms;
  bus.link[1] = LinkState::Lost;
  bus.detail[1] = "slave 2 stopped answering";
  runner.cycle(t);  // no publish
  std::vector<Event> changes;
  while (runner.pop_event(e))
    if (e.kind == EventKind::LinkChanged) changes.push_back(e);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].axis, 1);
  EXPECT_EQ(changes[0].text.view(), "link operational -> lost: slave 2 stopped answering");
  EXPECT_EQ(runner.snapshot(1).link, LinkState::Operational);  // stored at the last publish
  // The detail changes, the link stays lost: nothing to say now, the snapshot has it next.
  t += 1ms;
  bus.detail[1] = "restarting it (after 1000 ms)";
  runner.cycle(t);
  EXPECT_FALSE(runner.pop_event(e));
  runner.cycle(t += 1ms);
  runner.cycle(t += 1ms);
  EXPECT_EQ(runner.snapshot(1).link_detail.view(), "");
  runner.cycle(t += 1ms);  // 5 ms after the first: publishes
  EXPECT_EQ(runner.snapshot(1).link, LinkState::Lost);
  EXPECT_EQ(runner.snapshot(1).link_detail.view(), "restarting it (after 1000 ms)");
  EXPECT_EQ(runner.snapshot(1).link_since_ns, to_ns(TimePoint{1s + 1ms}));
  EXPECT_EQ(runner.snapshot(0).link_detail.view(), "");
}
