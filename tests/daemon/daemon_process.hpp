#pragma once
// Runs the real drivegated binary for an integration test: a config made from config/demo.yaml
// with the test's own gateway name, DDS domain and topic namespace, a NOTIFY_SOCKET the test
// listens on, and the daemon's log in a file. The process is killed when the object goes, and
// when the test process dies first (PR_SET_PDEATHSIG), so a crashed test leaves no daemon behind.
#include <sys/types.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <string>
#include <vector>

namespace drivegate::test {

// A DDS domain and namespace of this test process alone, so tests can run in parallel.
struct DdsIsolation {
  std::uint32_t domain;
  std::string ns;
};
DdsIsolation unique_dds(const std::string& tag);

// The demo configuration with gateway name, domain and namespace replaced, then `edit`ed; returns
// the file path.
std::string write_demo_config(const std::string& gateway, const DdsIsolation& dds,
                              const std::function<void(YAML::Node&)>& edit = {});

// A configuration given as text, in a file of this test process; returns the file path.
std::string write_config_text(const std::string& stem, const std::string& yaml);

// A NOTIFY_SOCKET like systemd's: it reads continuously (a unix datagram socket queues only a
// few messages; a sender whose queue is full blocks, as drivegated would in sd_notify).
class NotifySocket {
 public:
  NotifySocket();
  ~NotifySocket();
  [[nodiscard]] const std::string& path() const { return path_; }
  // Waits until a datagram containing `what` (e.g. "READY=1") has arrived.
  bool wait_for(const std::string& what, std::chrono::milliseconds timeout);
  // Waits until `n` datagrams containing `what` have arrived.
  bool wait_count(const std::string& what, std::size_t n, std::chrono::milliseconds timeout);
  // How many datagrams containing `what` have arrived so far.
  std::size_t count(const std::string& what);
  // Waits until every datagram sent to the socket before this call has been read (a marker sent
  // now comes back after them: the socket queues in order), so that count() includes them.
  bool drain(std::chrono::milliseconds timeout);

 private:
  void read_loop();
  int fd_ = -1;
  std::string path_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<std::string> received_;
  bool stop_ = false;
  std::size_t markers_ = 0;
  std::thread reader_;
};

class DaemonProcess {
 public:
  // `environment`: extra NAME=VALUE settings for the daemon (e.g. WATCHDOG_USEC).
  DaemonProcess(const std::string& config, const std::string& notify_socket, const std::string& log_level = "debug",
                const std::vector<std::string>& environment = {});
  ~DaemonProcess();
  [[nodiscard]] pid_t pid() const { return pid_; }
  // Sends a signal and waits for the exit; returns the exit status (or nullopt on timeout).
  std::optional<int> terminate(int signal, std::chrono::milliseconds timeout);
  // Whether the daemon is still running (a daemon that ended is reaped here).
  bool running();
  // Waits for the daemon to exit by itself; its exit status (or nullopt on timeout).
  std::optional<int> wait_exit(std::chrono::milliseconds timeout);
  [[nodiscard]] std::string log() const;
  // Resident set size in KiB from /proc, 0 if unknown.
  [[nodiscard]] long rss_kib() const;

 private:
  pid_t pid_ = -1;
  std::string log_path_;
};

}  // namespace drivegate::test
