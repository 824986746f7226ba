// The systemd watchdog is fed only while every cycle thread keeps its schedule: the real
// drivegated with WATCHDOG_USEC set, one cycle thread frozen by ptrace (the rest of the process
// runs on), the pings stop, and come back when the thread runs again.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/ptrace.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using namespace std::chrono_literals;

namespace {

// The thread of `pid` named `name` (drivegated names each cycle thread "dg-cycle-<bus>").
pid_t thread_named(pid_t pid, const std::string& name) {
  for (const auto& task : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task")) {
    std::ifstream in(task.path() / "comm");
    std::string comm;
    std::getline(in, comm);
    if (comm == name) return static_cast<pid_t>(std::stol(task.path().filename().string()));
  }
  return -1;
}

bool wait_log(test::DaemonProcess& d, const std::string& text, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (d.log().find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(20ms);  // polling a log file written by another process
  }
  return false;
}

TEST(Watchdog, IsWithheldWhileACycleThreadStalls) {
  const auto dds = test::unique_dds("wd");
  test::NotifySocket notify;
  test::DaemonProcess daemon(test::write_demo_config("wd", dds), notify.path(), "info", {"WATCHDOG_USEC=1000000"});
  ASSERT_TRUE(notify.wait_for("READY=1", 15s)) << daemon.log();
  ASSERT_TRUE(notify.wait_for("WATCHDOG=1", 20s)) << daemon.log();

  const pid_t cycle = thread_named(daemon.pid(), "dg-cycle-sim0");
  ASSERT_GT(cycle, 0) << "no thread dg-cycle-sim0 in drivegated";
  EXPECT_GT(thread_named(daemon.pid(), "dg-dds"), 0) << "the DDS bridge thread is named for top -H";
  ASSERT_EQ(::ptrace(PTRACE_SEIZE, cycle, nullptr, nullptr), 0) << std::strerror(errno);
  ASSERT_EQ(::ptrace(PTRACE_INTERRUPT, cycle, nullptr, nullptr), 0) << std::strerror(errno);
  int status = 0;
  ASSERT_EQ(::waitpid(cycle, &status, __WALL), cycle);
  ASSERT_TRUE(WIFSTOPPED(status));

  // The stall is noticed (the cycle is 1 ms, the limit 100 ms; the bound is for a loaded machine
  // under the sanitizers), and from then on no ping goes out. The pings sent before the notice
  // are counted first: they may still wait in the socket when the line is in the log.
  ASSERT_TRUE(wait_log(daemon, "withholding the watchdog ping", 20s)) << daemon.log();
  ASSERT_TRUE(notify.drain(5s));
  const std::size_t pings = notify.count("WATCHDOG=1");
  std::this_thread::sleep_for(1500ms);  // a time window: nothing must arrive in it (pings are every 500 ms)
  ASSERT_TRUE(notify.drain(5s));
  EXPECT_EQ(notify.count("WATCHDOG=1"), pings) << daemon.log();
  EXPECT_TRUE(daemon.running());

  ASSERT_EQ(::ptrace(PTRACE_DETACH, cycle, nullptr, nullptr), 0) << std::strerror(errno);
  EXPECT_TRUE(wait_log(daemon, "all cycle threads keep their schedule again", 20s)) << daemon.log();
  EXPECT_TRUE(notify.wait_count("WATCHDOG=1", pings + 1, 20s)) << daemon.log();
  EXPECT_EQ(daemon.terminate(SIGTERM, 20s), 0) << daemon.log();
}

}  // namespace
