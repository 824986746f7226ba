// The demo deployment's sim bus run through a BusRunner on virtual time, as drivegated's cycle
// thread runs it: commands in, replies out, axes moving; and not one heap allocation per cycle.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "config/loader.hpp"
#include "core/bus_runner.hpp"
#include "daemon/bus_factory.hpp"
#include "tests/support/alloc_counter.hpp"

using namespace drivegate;
using namespace std::chrono_literals;

namespace {

struct DemoBus : ::testing::Test {
  DemoBus() : plan(config::load_plan(DRIVEGATE_DEMO_CONFIG)) {
    const auto& bp = plan.buses.at(0);
    for (const auto& a : bp.axes) specs.push_back(a.spec);
    bus = daemon::make_bus(bp);
    runner = std::make_unique<core::BusRunner>(*bus, specs);
    bus->open(now);
    replies.reserve(4096);
    // Commands are refused until the drives have reported a status, as with a real bus.
    for (int i = 0; i < 5; ++i) cycle();
  }

  core::AxisIndex axis(const std::string& name) const {
    for (std::size_t i = 0; i < specs.size(); ++i)
      if (specs[i].name == name) return static_cast<core::AxisIndex>(i);
    throw std::runtime_error("demo.yaml has no axis " + name);
  }

  void push(core::AxisIndex a, core::CommandKind kind, double position = 0, double velocity = 0) {
    core::Command c;
    c.id = next_id++;
    c.axis = a;
    c.kind = kind;
    c.position = position;
    c.velocity = velocity;
    ASSERT_TRUE(runner->push_command(c));
  }

  // Runs cycles until the reply for `id` is final (or the cycle budget runs out).
  core::ReplyStatus run_until_final(core::CommandId id, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      cycle();
      for (const auto& r : replies)
        if (r.id == id && (r.status != core::ReplyStatus::Accepted)) return r.status;
    }
    return core::ReplyStatus::Accepted;
  }

  void cycle() {
    now += 1ms;
    runner->cycle(now);
    core::Reply r;
    while (runner->pop_reply(r)) replies.push_back(r);
    core::Event e;
    while (runner->pop_event(e)) {
    }
  }

  config::Plan plan;
  std::vector<core::AxisSpec> specs;
  std::unique_ptr<core::Bus> bus;
  std::unique_ptr<core::BusRunner> runner;
  std::vector<core::Reply> replies;
  core::TimePoint now{10s};
  core::CommandId next_id = 1;
};

}  // namespace

TEST_F(DemoBus, EnableAndMoveCompleteAtTheTarget) {
  const auto x = axis("x");
  push(x, core::CommandKind::Enable);
  ASSERT_EQ(run_until_final(1, 2000), core::ReplyStatus::Completed);
  EXPECT_EQ(runner->snapshot(x).state, core::AxisState::OperationEnabled);
  push(x, core::CommandKind::Move, 20.0);
  ASSERT_EQ(run_until_final(2, 20000), core::ReplyStatus::Completed);
  const auto s = runner->snapshot(x);
  EXPECT_TRUE(s.target_reached);
  EXPECT_NEAR(s.position, 20.0, 0.01);
}

TEST_F(DemoBus, CyclesAllocateNothingWhileAxesMove) {
  std::size_t allocations = 0;
  {
    test::AllocationScope scope;
    // Commands are pushed from this thread too; the queues are preallocated.
    for (core::AxisIndex a = 0; a < specs.size(); ++a) {
      core::Command c;
      c.id = next_id++;
      c.axis = a;
      c.kind = core::CommandKind::Enable;
      runner->push_command(c);
    }
    core::Reply r;
    core::Event e;
    for (int i = 0; i < 5000; ++i) {
      now += 1ms;
      if (i == 1000) {
        for (core::AxisIndex a = 0; a < specs.size(); ++a) {
          core::Command c;
          c.id = next_id++;
          c.axis = a;
          c.kind = specs[a].default_mode == core::Mode::ProfilePosition ? core::CommandKind::Move
                                                                         : core::CommandKind::Velocity;
          c.position = 5;
          c.velocity = specs[a].default_mode == core::Mode::ProfilePosition ? 0 : 1;
          runner->push_command(c);
        }
      }
      if (i > 1000) {
        for (core::AxisIndex a = 0; a < specs.size(); ++a) {
          core::Setpoint sp;
          sp.axis = a;
          sp.velocity = 1;
          runner->push_setpoint(sp);
        }
      }
      runner->cycle(now);
      while (runner->pop_reply(r)) {
      }
      while (runner->pop_event(e)) {
      }
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  bool moved = false;
  for (core::AxisIndex a = 0; a < specs.size(); ++a) {
    EXPECT_EQ(runner->snapshot(a).state, core::AxisState::OperationEnabled) << specs[a].name;
    moved = moved || std::fabs(runner->snapshot(a).position) > 0.1;
  }
  EXPECT_TRUE(moved);
}
