// Cycle timing benchmark: how late does a cycle start, (a) in a bare clock_nanosleep(TIMER_ABSTIME)
// loop and (b) in CycleThread running the workload from bench/workload.hpp? (a) is the floor this
// machine and kernel give; (b)/(a) is what our loop and the workload add.
//
// The two alternate in 1 s slices (a, b, a, b, ...), never in parallel, so they do not compete for
// a CPU and both see the same drift in machine load. Both use the same scheduling (--priority,
// --cpu) and the same overrun policy (skip missed slots). Figures only; nothing is asserted.
#include <time.h>

#include <charconv>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "bench/workload.hpp"
#include "core/timing_stats.hpp"
#include "daemon/cycle_thread.hpp"
#include "daemon/realtime.hpp"

namespace drivegate::bench {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

struct Options {
  int seconds = 10;
  int period_us = 1000;
  int priority = 0;
  int cpu = -1;
};

struct Result {
  core::LatencyHistogram lateness;
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;
  std::string note;
};

std::optional<int> parse_int(const char* text) {
  int value = 0;
  const std::string_view s(text);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return value;
}

void usage() {
  std::fprintf(stderr,
               "usage: bench_cycle_timing [--seconds N (>= 2, default 10)] [--period-us N (default 1000)]\n"
               "                          [--priority 0..99] [--cpu N] [workload options]\n");
}

// Options we do not know belong to the workload and are left alone.
std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    int* target = nullptr;
    if (arg == "--seconds") target = &o.seconds;
    if (arg == "--period-us") target = &o.period_us;
    if (arg == "--priority") target = &o.priority;
    if (arg == "--cpu") target = &o.cpu;
    if (arg == "--help" || arg == "-h") return std::nullopt;
    if (target == nullptr) continue;
    const std::optional<int> value = i + 1 < argc ? parse_int(argv[++i]) : std::nullopt;
    if (!value) {
      std::fprintf(stderr, "%s needs an integer value\n", argv[i - 1]);
      return std::nullopt;
    }
    *target = *value;
  }
  if (o.seconds < 2 || o.period_us <= 0 || o.priority < 0 || o.priority > 99) {
    std::fprintf(stderr, "need --seconds >= 2, --period-us > 0, --priority 0..99\n");
    return std::nullopt;
  }
  return o;
}

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * kNsPerSecond + ts.tv_nsec;
}

// (a): the same schedule as CycleThread with nothing else in the loop.
void bare_slice(const Options& o, std::int64_t slice_ns, Result& out) {
  std::thread([&] {
    out.note = daemon::apply_thread_scheduling(o.priority, o.cpu);
    daemon::prefault_stack();
    const std::int64_t period = std::int64_t{o.period_us} * 1000;
    const std::int64_t end = monotonic_ns() + slice_ns;
    std::int64_t next = monotonic_ns() + period;
    while (next < end) {
      const timespec ts{static_cast<time_t>(next / kNsPerSecond), static_cast<long>(next % kNsPerSecond)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
      out.lateness.record(monotonic_ns() - next);
      ++out.cycles;
      next += period;
      const std::int64_t now = monotonic_ns();
      if (now >= next) {
        ++out.overruns;
        next += ((now - next) / period + 1) * period;
      }
    }
  }).join();
}

// (b): CycleThread running the workload.
void cycle_thread_slice(const Options& o, std::int64_t slice_ns, const daemon::CycleThread::Body& body,
                        Result& out) {
  daemon::CycleThread thread({.period = std::chrono::microseconds(o.period_us), .priority = o.priority, .cpu = o.cpu},
                             body);
  if (!thread.start()) {
    out.note = thread.scheduling_note();
    return;
  }
  std::this_thread::sleep_for(std::chrono::nanoseconds(slice_ns));
  thread.stop();
  out.note = thread.scheduling_note();
  out.lateness.merge(thread.lifetime_histogram());
  out.cycles += thread.timing().cycles;
  out.overruns += thread.timing().overruns;
}

void print_row(const char* name, double a, double b, bool ratio) {
  std::printf("%-18s %16.1f %16.1f", name, a, b);
  if (ratio) {
    if (a > 0.0) {
      std::printf(" %10.2f", b / a);
    } else {
      std::printf(" %10s", "n/a");
    }
  }
  std::printf("\n");
}

double us(std::int64_t ns) { return static_cast<double>(ns) / 1000.0; }

int run(int argc, char** argv) {
  const std::optional<Options> options = parse(argc, argv);
  if (!options) {
    usage();
    return 2;
  }
  const Options& o = *options;
  daemon::CycleThread::Body body = make_workload(argc, argv);
  if (!body) body = [](core::TimePoint, std::uint64_t) {};

  const std::string memory_note = daemon::lock_memory();
  Result a;
  Result b;
  for (int slice = 0; slice < o.seconds; ++slice) {
    if (slice % 2 == 0) {
      bare_slice(o, kNsPerSecond, a);
    } else {
      cycle_thread_slice(o, kNsPerSecond, body, b);
    }
  }

  std::printf("cycle timing: period %d us, %d s in alternating 1 s slices ((a) %d s, (b) %d s), priority %d, cpu %d\n",
              o.period_us, o.seconds, (o.seconds + 1) / 2, o.seconds / 2, o.priority, o.cpu);
  std::printf("memory lock: %s\n", memory_note.empty() ? "ok" : memory_note.c_str());
  std::printf("scheduling (a): %s\n", a.note.empty() ? "as requested" : a.note.c_str());
  std::printf("scheduling (b): %s\n", b.note.empty() ? "as requested" : b.note.c_str());
  std::printf("%-18s %16s %16s %10s\n", "", "(a) bare loop", "(b) CycleThread", "b/a");
  std::printf("%-18s %16llu %16llu\n", "cycles", static_cast<unsigned long long>(a.cycles),
              static_cast<unsigned long long>(b.cycles));
  std::printf("%-18s %16llu %16llu\n", "overruns", static_cast<unsigned long long>(a.overruns),
              static_cast<unsigned long long>(b.overruns));
  print_row("lateness p50 [us]", us(a.lateness.percentile(50.0)), us(b.lateness.percentile(50.0)), true);
  print_row("lateness p99 [us]", us(a.lateness.percentile(99.0)), us(b.lateness.percentile(99.0)), true);
  print_row("lateness max [us]", us(a.lateness.max()), us(b.lateness.max()), true);
  return 0;
}

}  // namespace
}  // namespace drivegate::bench

int main(int argc, char** argv) { return drivegate::bench::run(argc, argv); }
