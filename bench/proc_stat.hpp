#pragma once
// CPU time of processes and threads from /proc, for the benchmarks that measure other processes
// (proc(5): fields 14 utime and 15 stime of /proc/PID/stat or /proc/PID/task/TID/stat; the "cpu"
// line of /proc/stat): a process' ticks in total and per thread, the whole machine's, their use
// over a phase in % of a core, and a fixed loop's thread CPU as a reference for the machine's speed.
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace drivegate::bench {

// Clock ticks (sysconf(_SC_CLK_TCK) a second) of utime + stime in the stat file `path`; the name
// between the parentheses to `name`. 0 when the file cannot be read.
inline unsigned long long stat_ticks(const std::string& path, std::string* name = nullptr) {
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  const auto open = text.find('(');
  const auto close = text.rfind(')');
  if (open == std::string::npos || close == std::string::npos) return 0;
  if (name != nullptr) *name = text.substr(open + 1, close - open - 1);
  std::istringstream rest(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return utime + stime;
}

// A process' CPU ticks, in total and per thread (by thread id, with its name).
struct Sample {
  unsigned long long process = 0;
  std::map<int, std::pair<std::string, unsigned long long>> threads;
};

inline Sample sample(pid_t pid) {
  Sample s;
  const std::string dir = "/proc/" + std::to_string(pid);
  s.process = stat_ticks(dir + "/stat");
  for (const auto& e : std::filesystem::directory_iterator(dir + "/task")) {
    std::string name;
    const auto ticks = stat_ticks(e.path().string() + "/stat", &name);
    s.threads[std::stoi(e.path().filename().string())] = {name, ticks};
  }
  return s;
}

// Busy and total jiffies of the whole machine (/proc/stat "cpu" line).
inline std::pair<unsigned long long, unsigned long long> machine_ticks() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  in >> cpu;
  unsigned long long v[8] = {};
  for (auto& x : v) in >> x;
  unsigned long long total = 0;
  for (auto x : v) total += x;
  return {total - v[3] - v[4], total};  // idle, iowait
}

// Thread CPU time of a fixed amount of arithmetic, in ms.
inline double reference_loop_ms() {
  timespec a{}, b{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &a);
  volatile std::uint64_t x = 1;
  for (int i = 0; i < 20'000'000; ++i) x = x * 6364136223846793005ULL + 1442695040888963407ULL;
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &b);
  return static_cast<double>(b.tv_sec - a.tv_sec) * 1e3 + static_cast<double>(b.tv_nsec - a.tv_nsec) / 1e6;
}

struct Usage {
  double process_pct = 0;
  std::map<std::string, std::pair<int, double>> threads;  // name -> (count, % of a core)
};

inline Usage usage(const Sample& a, const Sample& b, double seconds) {
  const double hz = static_cast<double>(::sysconf(_SC_CLK_TCK));
  const auto pct = [&](unsigned long long ticks) { return 100.0 * static_cast<double>(ticks) / hz / seconds; };
  Usage u;
  u.process_pct = pct(b.process - a.process);
  for (const auto& [tid, t] : b.threads) {
    const auto before = a.threads.find(tid);
    const unsigned long long start = before == a.threads.end() ? 0 : before->second.second;
    auto& slot = u.threads[t.first];
    ++slot.first;
    slot.second += pct(t.second - start);
  }
  return u;
}

// The process, then its threads by use; a cycle thread (dg-cycle-*) also per cycle of `cycle`.
inline void print_usage(const char* who, const Usage& u, double seconds, std::chrono::duration<double> cycle) {
  std::printf("  %-12s process %6.2f %% of a core\n", who, u.process_pct);
  std::vector<std::pair<std::string, std::pair<int, double>>> rows(u.threads.begin(), u.threads.end());
  std::sort(rows.begin(), rows.end(), [](const auto& x, const auto& y) { return x.second.second > y.second.second; });
  for (const auto& [name, v] : rows) {
    if (v.second < 0.005) continue;
    std::printf("    %-16s x%-2d %6.2f %%", name.c_str(), v.first, v.second);
    if (name.rfind("dg-cycle-", 0) == 0) {
      const double cycles = seconds / cycle.count();
      std::printf("   %.1f us per cycle", v.second / 100.0 * seconds / cycles * 1e6);
    }
    std::printf("\n");
  }
}

// The reference line: the machine's busy share between two machine_ticks() and what of it was not
// `ours_pct` (% of one core, summed over the measured processes, `ours` names them), and the
// fixed loop. Some virtual machines' /proc/stat lags or leaves out what the processes' own
// counters show: then the machine figure says nothing and is not printed as if it did.
inline void print_reference(const std::pair<unsigned long long, unsigned long long>& m0,
                            const std::pair<unsigned long long, unsigned long long>& m1, double ours_pct,
                            const char* ours, double reference_ms) {
  const double machine_pct = 100.0 * static_cast<double>(m1.first - m0.first) / static_cast<double>(m1.second - m0.second);
  const double other = machine_pct - ours_pct / static_cast<double>(::sysconf(_SC_NPROCESSORS_ONLN));
  if (other < -1.0)
    std::printf("  reference: machine busy not known (/proc/stat counts less than %s); fixed loop %.1f ms thread CPU\n",
                ours, reference_ms);
  else
    std::printf("  reference: machine busy %.1f %% of all cores (%.1f %% other than %s); fixed loop %.1f ms thread CPU\n",
                machine_pct, other, ours, reference_ms);
}

}  // namespace drivegate::bench
