#include "daemon/systemd_notify.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>

namespace drivegate::daemon {
namespace {

// A stand-in for the service manager: a datagram socket at a path unique to this process,
// announced through NOTIFY_SOCKET. Each gtest case runs in its own process under ctest, so
// changing the environment does not leak into other tests.
class FakeServiceManager {
 public:
  FakeServiceManager() {
    path_ = ::testing::TempDir() + "drivegate-notify-" + std::to_string(getpid()) + ".sock";
    unlink(path_.c_str());
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    EXPECT_LT(path_.size(), sizeof(addr.sun_path));
    std::memcpy(addr.sun_path, path_.c_str(), path_.size() + 1);
    // The receive timeout only bounds a failing test; a passing one never waits for it.
    timeval timeout{};
    timeout.tv_sec = 5;
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    EXPECT_EQ(bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0) << std::strerror(errno);
    setenv("NOTIFY_SOCKET", path_.c_str(), 1);
  }
  ~FakeServiceManager() {
    unsetenv("NOTIFY_SOCKET");
    close(fd_);
    unlink(path_.c_str());
  }
  FakeServiceManager(const FakeServiceManager&) = delete;
  FakeServiceManager& operator=(const FakeServiceManager&) = delete;

  std::string receive() {
    std::array<char, 4096> buf{};
    const ssize_t n = recv(fd_, buf.data(), buf.size(), 0);
    if (n < 0) return "<nothing received: " + std::string(std::strerror(errno)) + ">";
    return {buf.data(), static_cast<std::size_t>(n)};
  }

 private:
  std::string path_;
  int fd_ = -1;
};

TEST(SystemdNotifier, SendsEachMessageToTheNotifySocket) {
  FakeServiceManager manager;
  const SystemdNotifier notifier;
  EXPECT_TRUE(notifier.ready());
  EXPECT_EQ(manager.receive(), "READY=1");
  EXPECT_TRUE(notifier.status("2 buses, 5 axes operational"));
  EXPECT_EQ(manager.receive(), "STATUS=2 buses, 5 axes operational");
  EXPECT_TRUE(notifier.watchdog());
  EXPECT_EQ(manager.receive(), "WATCHDOG=1");
  EXPECT_TRUE(notifier.stopping());
  EXPECT_EQ(manager.receive(), "STOPPING=1");
}

TEST(SystemdNotifier, StatusCannotInjectOtherAssignments) {
  FakeServiceManager manager;
  const SystemdNotifier notifier;
  EXPECT_TRUE(notifier.status("bus can0 lost\nREADY=1"));
  EXPECT_EQ(manager.receive(), "STATUS=bus can0 lost READY=1");
}

TEST(SystemdNotifier, NoOpWithoutNotifySocket) {
  unsetenv("NOTIFY_SOCKET");
  const SystemdNotifier notifier;
  EXPECT_FALSE(notifier.ready());
  EXPECT_FALSE(notifier.status("x"));
  EXPECT_FALSE(notifier.watchdog());
  EXPECT_FALSE(notifier.stopping());
}

TEST(SystemdNotifier, WatchdogIntervalComesFromTheEnvironment) {
  const SystemdNotifier notifier;
  unsetenv("WATCHDOG_USEC");
  unsetenv("WATCHDOG_PID");
  EXPECT_FALSE(notifier.watchdog_interval().has_value());

  setenv("WATCHDOG_USEC", "5000000", 1);
  setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);
  const auto interval = notifier.watchdog_interval();
  ASSERT_TRUE(interval.has_value());
  EXPECT_EQ(*interval, std::chrono::seconds(5));

  // Meant for another process (inherited environment): not ours to serve.
  setenv("WATCHDOG_PID", std::to_string(getpid() + 1).c_str(), 1);
  EXPECT_FALSE(notifier.watchdog_interval().has_value());

  setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);
  setenv("WATCHDOG_USEC", "not-a-number", 1);
  EXPECT_FALSE(notifier.watchdog_interval().has_value());
  unsetenv("WATCHDOG_USEC");
  unsetenv("WATCHDOG_PID");
}

}  // namespace
}  // namespace drivegate::daemon
