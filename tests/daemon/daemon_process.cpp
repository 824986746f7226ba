#include "tests/daemon/daemon_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace drivegate::test {

namespace {
std::string temp_path(const std::string& stem) {
  static int counter = 0;
  return "/tmp/drivegate-test-" + std::to_string(getpid()) + "-" + std::to_string(++counter) + "-" + stem;
}
}  // namespace

DdsIsolation unique_dds(const std::string& tag) {
  // Domains above ~100 put RTPS ports into Linux's ephemeral range, so stay in 20..99 and separate
  // test processes further by namespace.
  return {20 + static_cast<std::uint32_t>(getpid()) % 80, "t" + std::to_string(getpid()) + "_" + tag};
}

std::string write_demo_config(const std::string& gateway, const DdsIsolation& dds,
                              const std::function<void(YAML::Node&)>& edit) {
  YAML::Node root = YAML::LoadFile(DRIVEGATE_DEMO_CONFIG);
  root["gateway"]["name"] = gateway;
  root["gateway"]["dds"]["domain"] = dds.domain;
  root["gateway"]["dds"]["namespace"] = dds.ns;
  if (edit) edit(root);
  const std::string path = temp_path(gateway + ".yaml");
  std::ofstream out(path);
  out << root << "\n";
  return path;
}

std::string write_config_text(const std::string& stem, const std::string& yaml) {
  const std::string path = temp_path(stem + ".yaml");
  std::ofstream out(path);
  out << yaml;
  if (!out) throw std::runtime_error("cannot write " + path);
  return path;
}

NotifySocket::NotifySocket() : path_(temp_path("notify.sock")) {
  fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path_.c_str(), sizeof(addr.sun_path) - 1);
  if (fd_ < 0 || bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0)
    throw std::runtime_error("cannot bind notify socket " + path_ + ": " + std::strerror(errno));
  reader_ = std::thread([this] { read_loop(); });
}

NotifySocket::~NotifySocket() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  reader_.join();
  close(fd_);
  unlink(path_.c_str());
}

void NotifySocket::read_loop() {
  for (;;) {
    {
      std::lock_guard lock(mutex_);
      if (stop_) return;
    }
    pollfd p{fd_, POLLIN, 0};
    if (poll(&p, 1, 50) <= 0) continue;
    char buf[4096];
    const auto n = recv(fd_, buf, sizeof buf, 0);
    if (n <= 0) continue;
    std::lock_guard lock(mutex_);
    received_.emplace_back(buf, static_cast<std::size_t>(n));
    arrived_.notify_all();
  }
}

std::size_t NotifySocket::count(const std::string& what) {
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const auto& m : received_) n += m.find(what) != std::string::npos ? 1U : 0U;
  return n;
}

bool NotifySocket::wait_for(const std::string& what, std::chrono::milliseconds timeout) {
  return wait_count(what, 1, timeout);
}

bool NotifySocket::wait_count(const std::string& what, std::size_t n, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  return arrived_.wait_for(lock, timeout, [&] {
    std::size_t seen = 0;
    for (const auto& m : received_) seen += m.find(what) != std::string::npos ? 1U : 0U;
    return seen >= n;
  });
}

bool NotifySocket::drain(std::chrono::milliseconds timeout) {
  std::string marker;
  {
    std::lock_guard lock(mutex_);
    marker = "X_TEST_DRAIN=" + std::to_string(++markers_);
  }
  const int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path_.c_str(), sizeof(addr.sun_path) - 1);
  const bool sent = fd >= 0 && sendto(fd, marker.data(), marker.size(), 0, reinterpret_cast<sockaddr*>(&addr),
                                      sizeof addr) == static_cast<ssize_t>(marker.size());
  if (fd >= 0) close(fd);
  return sent && wait_for(marker, timeout);
}

DaemonProcess::DaemonProcess(const std::string& config, const std::string& notify_socket, const std::string& log_level,
                             const std::vector<std::string>& environment)
    : log_path_(config + ".log") {
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    // Killed with the thread that started it (the test's), even when the test crashes; the check
    // covers a parent that died before prctl() took effect.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    const int fd = open(log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    setenv("NOTIFY_SOCKET", notify_socket.c_str(), 1);
    for (const auto& e : environment) {
      const auto eq = e.find('=');
      if (eq != std::string::npos) setenv(e.substr(0, eq).c_str(), e.substr(eq + 1).c_str(), 1);
    }
    execl(DRIVEGATED_PATH, DRIVEGATED_PATH, "--config", config.c_str(), "--log-level", log_level.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
}

DaemonProcess::~DaemonProcess() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

std::optional<int> DaemonProcess::terminate(int signal, std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return std::nullopt;
  kill(pid_, signal);
  return wait_exit(timeout);
}

std::optional<int> DaemonProcess::wait_exit(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return std::nullopt;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      pid_ = -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling waitpid for a child's exit
  }
  return std::nullopt;
}

bool DaemonProcess::running() {
  if (pid_ <= 0) return false;
  if (waitpid(pid_, nullptr, WNOHANG) == 0) return true;
  pid_ = -1;
  return false;
}

std::string DaemonProcess::log() const {
  std::ifstream in(log_path_);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

long DaemonProcess::rss_kib() const {
  std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  return 0;
}

}  // namespace drivegate::test
