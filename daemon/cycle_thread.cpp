#include "daemon/cycle_thread.hpp"

#include <pthread.h>

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <system_error>
#include <utility>

#include "daemon/realtime.hpp"

namespace drivegate::daemon {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * kNsPerSecond + ts.tv_nsec;
}

void sleep_until(std::int64_t deadline_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / kNsPerSecond);
  ts.tv_nsec = static_cast<long>(deadline_ns % kNsPerSecond);
  // A signal interrupts the sleep; the deadline is absolute, so just sleep again.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

CycleThread::CycleThread(Schedule schedule, Body body, Between between)
    : schedule_(std::move(schedule)), body_(std::move(body)), between_(std::move(between)) {}

CycleThread::~CycleThread() { stop(); }

bool CycleThread::start() {
  if (launched_) {
    return false;
  }
  if (schedule_.period <= core::Duration::zero()) {
    note_ = "cycle period must be positive";
    return false;
  }
  if (!body_) {
    note_ = "cycle thread has no body";
    return false;
  }
  launched_ = true;
  try {
    thread_ = std::thread([this] { run(); });
  } catch (const std::system_error& e) {
    note_ = std::string("cannot create cycle thread: ") + e.what();
    return false;
  }
  started_.wait(false, std::memory_order_acquire);
  return true;
}

void CycleThread::stop() {
  stop_requested_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

bool CycleThread::healthy(core::TimePoint now) const noexcept {
  if (!running()) return false;
  const std::int64_t allowed = std::max<std::int64_t>(10 * schedule_.period.count(), 100'000'000);
  return core::to_ns(now) - last_start_ns_.load(std::memory_order_acquire) <= allowed;
}

std::string CycleThread::scheduling_note() const { return note_; }

void CycleThread::run() noexcept {
  // Set-up may allocate and fault; the loop below must not.
  if (!schedule_.name.empty()) {
    // The kernel keeps 15 characters; ps -L, top -H and /proc/PID/task/TID/comm show them.
    char name[16] = {};
    schedule_.name.copy(name, sizeof name - 1);
    ::pthread_setname_np(::pthread_self(), name);
  }
  try {
    note_ = apply_thread_scheduling(schedule_.priority, schedule_.cpu);
  } catch (...) {
    note_.clear();  // out of memory while building the message: nothing useful to report
  }
  prefault_stack();

  const std::int64_t period = schedule_.period.count();
  const std::int64_t window = std::max(schedule_.status_window.count(), period);
  TimingSnapshot snap;
  snap.period_ns = period;
  timing_.store(snap);

  const std::int64_t start_ns = monotonic_ns();
  std::int64_t next = start_ns + period;
  std::int64_t window_start = 0;
  std::uint64_t window_cycles = 0;
  last_start_ns_.store(start_ns, std::memory_order_release);
  running_.store(true, std::memory_order_release);
  started_.store(true, std::memory_order_release);
  started_.notify_all();

  try {
    for (std::uint64_t cycle = 0;; ++cycle) {
      if (between_ && !stop_requested_.load(std::memory_order_acquire)) between_(core::TimePoint{core::Duration{next}});
      sleep_until(next);
      if (stop_requested_.load(std::memory_order_acquire)) break;
      const std::int64_t wake = monotonic_ns();
      const std::int64_t lateness = wake - next;

      // Roll the status window before this cycle joins the next one: n cycle starts in the old
      // window plus this one span n periods.
      if (window_cycles > 0 && wake - window_start >= window) {
        snap.lateness_p50_ns = window_.percentile(50.0);
        snap.lateness_p99_ns = window_.percentile(99.0);
        snap.lateness_max_ns = window_.max();
        snap.achieved_period_ns = (wake - window_start) / static_cast<std::int64_t>(window_cycles);
        lifetime_.merge(window_);
        window_.reset();
        window_cycles = 0;
      }
      if (window_cycles == 0) window_start = wake;
      ++window_cycles;
      window_.record(lateness);
      snap.lateness_lifetime_max_ns = std::max(snap.lateness_lifetime_max_ns, lateness);
      snap.cycles = cycle + 1;
      snap.last_cycle_ns = wake;
      timing_.store(snap);
      last_start_ns_.store(wake, std::memory_order_release);

      body_(core::TimePoint{core::Duration{wake}}, cycle);

      next += period;
      const std::int64_t end = monotonic_ns();
      if (end >= next) {
        // Overrun: the next planned start has passed. Skip to the first slot still ahead rather
        // than running the missed cycles back to back.
        const std::int64_t missed = (end - next) / period + 1;
        ++snap.overruns;
        snap.skipped_slots += static_cast<std::uint64_t>(missed);
        next += missed * period;
      }
    }
  } catch (...) {
    body_failed_.store(true, std::memory_order_release);
  }

  lifetime_.merge(window_);
  window_.reset();
  timing_.store(snap);
  running_.store(false, std::memory_order_release);
}

}  // namespace drivegate::daemon
