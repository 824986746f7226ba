#include "daemon/realtime.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

namespace drivegate::daemon {
namespace {

// What a thread ended up with.
struct Applied {
  std::string note;
  int policy = -1;
  int priority = -1;
  cpu_set_t cpus{};
};

// Scheduling changes apply to the calling thread; run them on a throw-away thread so the test
// runner keeps its own, and read back what the kernel says the thread got.
Applied on_fresh_thread(int priority, int cpu) {
  Applied a;
  std::thread([&] {
    a.note = apply_thread_scheduling(priority, cpu);
    sched_param param{};
    pthread_getschedparam(pthread_self(), &a.policy, &param);
    a.priority = param.sched_priority;
    CPU_ZERO(&a.cpus);
    sched_getaffinity(0, sizeof a.cpus, &a.cpus);
  }).join();
  return a;
}

// VmLck of this process in kB (locked memory), -1 when unknown.
long locked_kib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmLck:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  return -1;
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

TEST(Realtime, NothingRequestedKeepsTheNormalScheduler) {
  const Applied a = on_fresh_thread(0, -1);
  EXPECT_EQ(a.note, "");
  EXPECT_EQ(a.policy, SCHED_OTHER);
}

TEST(Realtime, PinningToAnAllowedCpuPinsTheThread) {
  const int cpu = first_allowed_cpu();
  ASSERT_GE(cpu, 0);
  const Applied a = on_fresh_thread(0, cpu);
  EXPECT_EQ(a.note, "");
  EXPECT_EQ(CPU_COUNT(&a.cpus), 1);
  EXPECT_TRUE(CPU_ISSET(static_cast<std::size_t>(cpu), &a.cpus));
}

TEST(Realtime, UnknownCpuIsNamedWithTheAllowedOnes) {
  const std::string note = on_fresh_thread(0, 5000).note;
  EXPECT_NE(note.find("CPU 5000"), std::string::npos) << note;
  EXPECT_NE(note.find("allowed CPUs"), std::string::npos) << note;
}

TEST(Realtime, OutOfRangePriorityIsRejected) {
  EXPECT_NE(on_fresh_thread(100, -1).note.find("1..99"), std::string::npos);
  EXPECT_NE(on_fresh_thread(-3, -1).note.find("1..99"), std::string::npos);
}

// Whether this machine grants SCHED_FIFO depends on capabilities and cgroups: without a message
// the thread must really run SCHED_FIFO at that priority; with one, it says what is missing and
// the thread stays on the normal scheduler.
TEST(Realtime, FifoAppliesOrSaysWhatIsMissing) {
  const Applied a = on_fresh_thread(10, -1);
  if (a.note.empty()) {
    EXPECT_EQ(a.policy, SCHED_FIFO);
    EXPECT_EQ(a.priority, 10);
  } else {
    EXPECT_NE(a.note.find("SCHED_FIFO"), std::string::npos) << a.note;
    EXPECT_NE(a.note.find("normal scheduling"), std::string::npos) << a.note;
    EXPECT_EQ(a.policy, SCHED_OTHER);
  }
}

// AddressSanitizer is on (gcc says so with __SANITIZE_ADDRESS__, clang 14 only through __has_feature).
#if defined(__SANITIZE_ADDRESS__)
#define DRIVEGATE_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DRIVEGATE_TEST_ASAN 1
#endif
#endif

// Without a message the process' memory is locked (VmLck covers what is resident); with one, it
// names mlockall and nothing is locked.
TEST(Realtime, LockMemoryLocksOrSaysWhatIsMissing) {
  const std::string note = lock_memory();
  if (note.empty()) {
#if defined(DRIVEGATE_TEST_ASAN)
    // AddressSanitizer turns mlockall into a no-op (locking its shadow memory would take the
    // machine's RAM): nothing to read back in that build.
    munlockall();
    return;
#endif
    EXPECT_GT(locked_kib(), 0);
    munlockall();
    EXPECT_EQ(locked_kib(), 0);
  } else {
    EXPECT_NE(note.find("mlockall"), std::string::npos) << note;
    EXPECT_EQ(locked_kib(), 0);
  }
}

// The stack a cycle thread will use is touched up front, so the cycle path never faults a stack
// page in: on a fresh stack the first prefault takes the page faults, doing it again (as deep a
// stack) takes none. (The thread gets a stack of its own: glibc reuses the stacks of ended
// threads, whose pages are already in.)
TEST(Realtime, PrefaultStackTakesTheStackFaultsUpFront) {
  struct Result {
    long first = 0;
    long again = 0;
  } result;
  constexpr std::size_t kStack = 1024 * 1024;
  void* stack = mmap(nullptr, kStack, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_STACK, -1, 0);
  ASSERT_NE(stack, MAP_FAILED);
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstack(&attr, stack, kStack);
  pthread_t thread;
  const auto body = [](void* arg) -> void* {
    auto* r = static_cast<Result*>(arg);
    const auto faults = [] {
      rusage u{};
      getrusage(RUSAGE_THREAD, &u);
      return u.ru_minflt;
    };
    const long f0 = faults();
    prefault_stack();
    const long f1 = faults();
    prefault_stack();
    r->first = f1 - f0;
    r->again = faults() - f1;
    return nullptr;
  };
  ASSERT_EQ(pthread_create(&thread, &attr, body, &result), 0);
  pthread_join(thread, nullptr);
  pthread_attr_destroy(&attr);
  munmap(stack, kStack);
  EXPECT_GE(result.first, static_cast<long>(kPrefaultStackBytes / 4096) / 2);
  EXPECT_LE(result.again, 2);
}

}  // namespace
}  // namespace drivegate::daemon
