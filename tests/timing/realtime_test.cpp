#include "daemon/realtime.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mman.h>

#include <string>
#include <thread>

namespace drivegate::daemon {
namespace {

// Scheduling changes apply to the calling thread; run them on a throw-away thread so the test
// runner keeps its own.
std::string on_fresh_thread(int priority, int cpu) {
  std::string note;
  std::thread([&] { note = apply_thread_scheduling(priority, cpu); }).join();
  return note;
}

int first_allowed_cpu() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return -1;
  for (std::size_t cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &set)) return static_cast<int>(cpu);
  }
  return -1;
}

TEST(Realtime, NothingRequestedIsFine) { EXPECT_EQ(on_fresh_thread(0, -1), ""); }

TEST(Realtime, PinningToAnAllowedCpuWorks) {
  const int cpu = first_allowed_cpu();
  ASSERT_GE(cpu, 0);
  EXPECT_EQ(on_fresh_thread(0, cpu), "");
}

TEST(Realtime, UnknownCpuIsNamedWithTheAllowedOnes) {
  const std::string note = on_fresh_thread(0, 5000);
  EXPECT_NE(note.find("CPU 5000"), std::string::npos) << note;
  EXPECT_NE(note.find("allowed CPUs"), std::string::npos) << note;
}

TEST(Realtime, OutOfRangePriorityIsRejected) {
  EXPECT_NE(on_fresh_thread(100, -1).find("1..99"), std::string::npos);
  EXPECT_NE(on_fresh_thread(-3, -1).find("1..99"), std::string::npos);
}

TEST(Realtime, FifoEitherAppliesOrSaysWhatIsMissing) {
  // Whether this machine grants SCHED_FIFO depends on capabilities and cgroups; either outcome
  // is fine as long as a refusal names the fix.
  const std::string note = on_fresh_thread(10, -1);
  if (!note.empty()) {
    EXPECT_NE(note.find("SCHED_FIFO"), std::string::npos) << note;
    EXPECT_NE(note.find("normal scheduling"), std::string::npos) << note;
  }
}

TEST(Realtime, LockMemoryEitherLocksOrSaysWhatIsMissing) {
  const std::string note = lock_memory();
  if (note.empty()) {
    munlockall();
  } else {
    EXPECT_NE(note.find("mlockall"), std::string::npos) << note;
  }
}

TEST(Realtime, PrefaultStackRunsOnASmallThread) {
  std::thread([] { prefault_stack(); }).join();
  SUCCEED();
}

}  // namespace
}  // namespace drivegate::daemon
