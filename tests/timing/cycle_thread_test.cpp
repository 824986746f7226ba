#include "daemon/cycle_thread.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <thread>

#include "tests/support/alloc_counter.hpp"

namespace drivegate::daemon {
namespace {

using namespace std::chrono_literals;

// A real-time thread can only be observed in real time: poll for a condition with a generous
// deadline (the poll interval is not what the test relies on, the condition is).
bool eventually(const std::function<bool()>& condition, std::chrono::seconds limit = 20s) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return condition();
}

core::TimePoint monotonic_now() { return core::SteadyClock{}.now(); }

TEST(CycleThread, RefusesBadScheduleOrMissingBody) {
  CycleThread no_period({.period = 0ms}, [](core::TimePoint, std::uint64_t) {});
  EXPECT_FALSE(no_period.start());
  EXPECT_NE(no_period.scheduling_note().find("period"), std::string::npos);

  CycleThread no_body({.period = 1ms}, CycleThread::Body{});
  EXPECT_FALSE(no_body.start());
  EXPECT_NE(no_body.scheduling_note().find("body"), std::string::npos);
  no_body.stop();  // harmless without a thread
}

TEST(CycleThread, CountsCyclesAndPublishesTiming) {
  std::atomic<std::uint64_t> calls{0};
  std::atomic<std::uint64_t> expected_cycle{0};
  std::atomic<bool> in_order{true};
  CycleThread thread({.period = 1ms, .status_window = 50ms}, [&](core::TimePoint, std::uint64_t cycle) {
    if (cycle != expected_cycle.load()) in_order = false;
    expected_cycle = cycle + 1;
    ++calls;
  });
  EXPECT_FALSE(thread.healthy(monotonic_now()));
  ASSERT_TRUE(thread.start());
  EXPECT_FALSE(thread.start());  // once only
  EXPECT_TRUE(thread.running());
  EXPECT_TRUE(thread.healthy(monotonic_now()));

  ASSERT_TRUE(eventually([&] { return thread.timing().cycles >= 5; }));
  const TimingSnapshot first = thread.timing();
  // Percentiles appear once a status window has been rolled.
  ASSERT_TRUE(eventually([&] { return thread.timing().achieved_period_ns > 0; }));
  const TimingSnapshot later = thread.timing();
  EXPECT_TRUE(thread.healthy(monotonic_now()));
  // A last cycle a second ago is too old for a 1 ms thread (limit: max(10 periods, 100 ms)).
  EXPECT_FALSE(thread.healthy(monotonic_now() + 1s));

  thread.stop();
  EXPECT_FALSE(thread.running());
  EXPECT_FALSE(thread.healthy(monotonic_now()));
  const TimingSnapshot last = thread.timing();

  EXPECT_EQ(first.period_ns, 1'000'000);
  EXPECT_GT(later.cycles, first.cycles);
  EXPECT_GT(later.last_cycle_ns, first.last_cycle_ns);
  // Cycle starts never come before their planned time, so the mean spacing cannot be much
  // shorter than the period (it is longer when the machine is loaded).
  EXPECT_GE(later.achieved_period_ns, 900'000);
  EXPECT_LE(later.lateness_p50_ns, later.lateness_p99_ns);
  EXPECT_LE(later.lateness_p99_ns, later.lateness_max_ns);
  EXPECT_LE(later.lateness_max_ns, later.lateness_lifetime_max_ns);
  EXPECT_TRUE(in_order);
  // stop() joined: every body call is accounted for and no more will come.
  EXPECT_EQ(last.cycles, calls.load());
  EXPECT_EQ(thread.lifetime_histogram().count(), calls.load());
  EXPECT_EQ(thread.lifetime_histogram().max(), last.lateness_lifetime_max_ns);
  EXPECT_FALSE(thread.body_failed());
  thread.stop();  // idempotent
}

TEST(CycleThread, OverrunsAreCountedAndMissedSlotsSkipped) {
  // Every 4th cycle the body takes 7 ms in a 2 ms period: that cycle overruns and the next
  // planned starts that have passed (at least 3 of them) are skipped, not run back to back.
  std::atomic<std::uint64_t> slow_done{0};
  CycleThread thread({.period = 2ms}, [&](core::TimePoint, std::uint64_t cycle) {
    if (cycle % 4 == 1) {
      std::this_thread::sleep_for(7ms);
      ++slow_done;
    }
  });
  ASSERT_TRUE(thread.start());
  ASSERT_TRUE(eventually([&] { return slow_done.load() >= 5; }));
  thread.stop();
  const TimingSnapshot t = thread.timing();
  EXPECT_GE(t.overruns, slow_done.load());
  EXPECT_GE(t.skipped_slots, 3 * slow_done.load());
  EXPECT_GE(t.skipped_slots, t.overruns);
}

TEST(CycleThread, LoopAddsNoAllocation) {
  // The body measures what the cycle thread allocated between the end of one call and the start
  // of the next: that is the loop alone (sleep, histogram, window roll, seqlock publish).
  std::uint64_t loop_allocations = 0;  // cycle thread only until stop() joined
  std::size_t at_end = 0;
  std::atomic<std::uint64_t> calls{0};
  CycleThread thread({.period = 1ms, .status_window = 10ms}, [&](core::TimePoint, std::uint64_t cycle) {
    const std::size_t now = test::thread_allocations();
    if (cycle > 0) loop_allocations += now - at_end;
    at_end = test::thread_allocations();
    ++calls;
  });
  ASSERT_TRUE(thread.start());
  // Enough cycles for several status windows to roll.
  ASSERT_TRUE(eventually([&] { return calls.load() >= 100 && thread.timing().achieved_period_ns > 0; }));
  thread.stop();
  EXPECT_EQ(loop_allocations, 0U);
}

TEST(CycleThread, BetweenGetsEachNextStartAndTheCycleStillStartsThere) {
  // `between` is called before every sleep with the next cycle's start; the body's `now` of that
  // cycle is never before it, and what `between` spends of the period does not move the schedule.
  constexpr std::int64_t kPeriod = 2'000'000;
  std::int64_t announced = 0;     // cycle thread only until stop() joined
  std::int64_t first_start = 0;
  std::uint64_t early = 0;        // cycles that started before the start `between` was given
  std::uint64_t off_grid = 0;     // announced starts not on the period grid
  std::atomic<std::uint64_t> calls{0};
  CycleThread thread(
      {.period = std::chrono::nanoseconds(kPeriod)},
      [&](core::TimePoint now, std::uint64_t) {
        if (core::to_ns(now) < announced) ++early;
        ++calls;
      },
      [&](core::TimePoint deadline) {
        const std::int64_t d = core::to_ns(deadline);
        if (first_start == 0) first_start = d;
        if ((d - first_start) % kPeriod != 0) ++off_grid;
        announced = d;
        // Busy until half a period before the deadline, as a bus serving frames would be.
        while (core::to_ns(monotonic_now()) < d - kPeriod / 2) {
        }
      });
  ASSERT_TRUE(thread.start());
  ASSERT_TRUE(eventually([&] { return calls.load() >= 50; }));
  thread.stop();
  EXPECT_EQ(early, 0U);
  EXPECT_EQ(off_grid, 0U);
}

TEST(CycleThread, BodyExceptionEndsThreadWithoutCrash) {
  CycleThread thread({.period = 1ms}, [](core::TimePoint, std::uint64_t cycle) {
    if (cycle == 3) throw std::runtime_error("bug in a bus engine");
  });
  ASSERT_TRUE(thread.start());
  ASSERT_TRUE(eventually([&] { return !thread.running(); }));
  EXPECT_TRUE(thread.body_failed());
  EXPECT_FALSE(thread.healthy(monotonic_now()));
  EXPECT_EQ(thread.timing().cycles, 4U);
}

TEST(CycleThread, SchedulingProblemsAreReportedNotFatal) {
  std::atomic<std::uint64_t> calls{0};
  CycleThread thread({.period = 1ms, .priority = 150, .cpu = 100'000},
                     [&](core::TimePoint, std::uint64_t) { ++calls; });
  ASSERT_TRUE(thread.start());
  const std::string note = thread.scheduling_note();
  EXPECT_NE(note.find("1..99"), std::string::npos) << note;
  EXPECT_NE(note.find("CPU 100000"), std::string::npos) << note;
  ASSERT_TRUE(eventually([&] { return calls.load() >= 3; }));
}

TEST(CycleThread, DestructorStopsTheThread) {
  std::atomic<std::uint64_t> calls{0};
  {
    CycleThread thread({.period = 1ms}, [&](core::TimePoint, std::uint64_t) { ++calls; });
    ASSERT_TRUE(thread.start());
    ASSERT_TRUE(eventually([&] { return calls.load() >= 2; }));
  }
  const std::uint64_t after = calls.load();
  EXPECT_GE(after, 2U);
}

}  // namespace
}  // namespace drivegate::daemon
