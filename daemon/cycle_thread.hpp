#pragma once
// One cycle thread per bus (DESIGN.md §3): runs a body on an absolute-time schedule
// (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)), optionally SCHED_FIFO on a fixed CPU, and
// publishes its timing health without locks through a seqlock.
//
// The loop adds no allocation, lock, logging or blocking beyond the sleep itself; what the body
// does is the body's business (it runs the bus' sans-I/O engines and must follow the same rules).
// Before each sleep an optional `between` function gets the next cycle's start: a bus answers its
// acyclic traffic there (core::Bus::serve_until). It must return by that deadline; the final wake
// is still the absolute-time sleep, so the cycle starts as precisely as without it.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>

#include "core/clock.hpp"
#include "core/seqlock.hpp"
#include "core/timing_stats.hpp"

namespace drivegate::daemon {

// Timing of one cycle thread as seen from other threads. Lateness = wake-up time - planned time.
struct TimingSnapshot {
  std::int64_t period_ns = 0;  // configured
  std::uint64_t cycles = 0;    // body calls so far
  std::uint64_t overruns = 0;  // cycles that ended after the next planned start
  std::uint64_t skipped_slots = 0;  // planned starts dropped to catch up after overruns
  // Over the last completed status window (all zero until the first window completes).
  std::int64_t lateness_p50_ns = 0;
  std::int64_t lateness_p99_ns = 0;
  std::int64_t lateness_max_ns = 0;
  std::int64_t achieved_period_ns = 0;  // mean time between cycle starts
  std::int64_t lateness_lifetime_max_ns = 0;
  std::int64_t last_cycle_ns = 0;  // CLOCK_MONOTONIC time of the last cycle start (0: none yet)
};

class CycleThread {
 public:
  struct Schedule {
    core::Duration period{};
    int priority = 0;  // SCHED_FIFO 1..99 when > 0
    int cpu = -1;      // pinned to this CPU when >= 0
    core::Duration status_window = std::chrono::seconds(1);  // how often percentiles are rolled
    std::string name = {};  // thread name shown by ps/top (at most 15 characters are kept)
  };
  // now: the CLOCK_MONOTONIC wake-up time of this cycle; cycle: 0, 1, 2, ...
  using Body = std::function<void(core::TimePoint now, std::uint64_t cycle)>;
  // deadline: the CLOCK_MONOTONIC time of the next cycle's start.
  using Between = std::function<void(core::TimePoint deadline)>;

  CycleThread(Schedule schedule, Body body, Between between = {});
  ~CycleThread();  // stops the thread
  CycleThread(const CycleThread&) = delete;
  CycleThread& operator=(const CycleThread&) = delete;

  // Spawns the thread and returns once it has applied its scheduling. Returns false (and does
  // nothing) when already started, when the period is not positive or the body is empty;
  // the reason is then in scheduling_note(). A thread runs once: start() after stop() is refused.
  bool start();
  // Requests stop and joins; waits at most about one period. The body is not called after stop()
  // returns. Safe to call more than once or without start().
  void stop();

  [[nodiscard]] bool running() const noexcept { return running_.load(std::memory_order_acquire); }
  // The body threw: the thread ended (and is not healthy). The body must not throw; this keeps a
  // bug in one bus from taking the whole daemon down.
  [[nodiscard]] bool body_failed() const noexcept { return body_failed_.load(std::memory_order_acquire); }
  // Running, and the last cycle started within max(10 periods, 100 ms) before now.
  [[nodiscard]] bool healthy(core::TimePoint now) const noexcept;
  [[nodiscard]] TimingSnapshot timing() const noexcept { return timing_.load(); }
  // Why scheduling is not what was asked for (missing CAP_SYS_NICE, bad CPU, ...); empty when
  // all was applied. Valid after start() returned.
  [[nodiscard]] std::string scheduling_note() const;
  // Every lateness recorded over the thread's life. Only valid once stop() has returned.
  [[nodiscard]] const core::LatencyHistogram& lifetime_histogram() const noexcept { return lifetime_; }
  [[nodiscard]] const Schedule& schedule() const noexcept { return schedule_; }

 private:
  void run() noexcept;

  Schedule schedule_;
  Body body_;
  Between between_;
  std::thread thread_;
  std::string note_;  // written by the thread before started_ is released, then read-only
  bool launched_ = false;  // start() was called; control thread only
  std::atomic<bool> started_{false};
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> body_failed_{false};
  // The thread's start, then each cycle's: healthy() reads this one word, never timing_, whose
  // seqlock would keep a reader waiting for as long as the thread stays stopped inside a store
  // (preempted, or frozen by a debugger): the supervisor must not hang on the thread it watches.
  std::atomic<std::int64_t> last_start_ns_{0};
  core::LatencyHistogram window_;    // cycle thread only
  core::LatencyHistogram lifetime_;  // cycle thread only while running
  core::Seqlock<TimingSnapshot> timing_;
};

}  // namespace drivegate::daemon
