#pragma once
// The drivegate-sim binary as a child process of an end-to-end test: the simulated drives of a
// config's udp-multicast canopen bus, controlled through its stdin (one command a line, one answer
// line each) and observed through its `status` answer. Killed when the object goes, and when the
// test process dies first (PR_SET_PDEATHSIG).
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "tests/support/pipe_lines.hpp"

namespace drivegate::test {

// The virtual CAN bus of one test: a 239.x group of the test process and a port that no DDS
// participant of a parallel test can hold.
struct BusAddress {
  std::string group;
  std::uint16_t port = 0;
};
BusAddress unique_bus_address(unsigned slot);

class SimProcess {
 public:
  // Starts `drivegate-sim CONFIG`; its stderr goes to CONFIG.sim.log.
  explicit SimProcess(const std::string& config);
  ~SimProcess();
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  // The ready line ("drivegate-sim: N nodes on udp-multicast GROUP:PORT"), printed once the drives
  // have booted; nullopt when none came in time.
  std::optional<std::string> wait_ready(std::chrono::milliseconds timeout);
  // Sends one command line and returns the simulator's answer ("" when none came in time).
  std::string command(const std::string& line, std::chrono::milliseconds timeout = std::chrono::seconds(2));
  // Sends `line` until `done(answer)` holds or the timeout passes (an answer may take 5 s); true
  // when it held. The last answer is left in `last`.
  bool wait_answer(const std::string& line, const std::function<bool(const std::string&)>& done,
                   std::chrono::milliseconds timeout, std::string& last);
  // wait_answer for `status`.
  bool wait_status(const std::function<bool(const std::string&)>& done, std::chrono::milliseconds timeout,
                   std::string& last) {
    return wait_answer("status", done, timeout, last);
  }
  [[nodiscard]] std::string log() const;
  [[nodiscard]] pid_t pid() const { return pid_; }

 private:
  std::optional<std::string> next_line(std::chrono::milliseconds timeout);

  pid_t pid_ = -1;
  int stdin_ = -1;
  int stdout_ = -1;
  std::string log_path_;
  PipeLines lines_;
};

// The part of a `status` answer about one node ("can0:3 stoeber-sd6 nmt=operational
// state=fault fault=0x7500"), empty when the node is not in it.
std::string node_status(const std::string& status, const std::string& bus, int node);

}  // namespace drivegate::test
