#pragma once
// Network namespaces and veth pairs for tests and benchmarks that need real Ethernet interfaces
// (DESIGN.md §5, §8: EtherCAT and PROFINET over veth pairs inside namespaces the test creates and
// removes). Everything is made with iproute2's `ip`, named uniquely per process
// ("dgt<pid>_<n><kind>", at most 15 characters, so parallel tests never meet), and removed by the
// destructors, also when a test fails or throws. Objects a crashed earlier run left behind (their
// pid no longer alive) are removed when the first namespace of a process is made. Traffic stays in
// the namespaces: tests put both ends of a pair into namespaces of their own.
//
// Needs root (CAP_NET_ADMIN, CAP_SYS_ADMIN) and `ip`; netns_unavailable() says why not, for
// GTEST_SKIP. No GoogleTest here, so benchmarks use it too.
#include <sys/types.h>

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tests/support/pipe_lines.hpp"
#include "tests/support/run_program.hpp"

namespace drivegate::test {

// "" when this process can make network namespaces and veth pairs; otherwise the reason (not
// root, no CAP_NET_ADMIN / CAP_SYS_ADMIN, `ip` missing, the kernel refused). Probed once.
const std::string& netns_unavailable();

// Runs `ip ARGS...` (iproute2, found in the sbin and bin directories).
RunResult run_ip(const std::vector<std::string>& args);

// The prefix of every object made here, and a fresh unique name with it: "dgt<pid>_<n><kind>".
inline constexpr const char* kNetnsPrefix = "dgt";
std::string unique_net_name(char kind);
// Removes namespaces and interfaces (in this process's namespace) with our prefix whose pid is no
// longer alive. Returns how many objects it removed.
int remove_stale_net_objects();

class NetNamespace {
 public:
  // `ip netns add`, then loopback up inside. Throws std::runtime_error with ip's output.
  NetNamespace();
  ~NetNamespace();
  NetNamespace(const NetNamespace&) = delete;
  NetNamespace& operator=(const NetNamespace&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  // `ip -n NAME ARGS...`
  RunResult ip(const std::vector<std::string>& args) const;

 private:
  std::string name_;
};

// The calling thread runs in `ns` from here to the end of the scope (sockets it opens meanwhile
// stay in `ns`). Throws std::runtime_error when setns fails.
class NetnsScope {
 public:
  explicit NetnsScope(const NetNamespace& ns);
  ~NetnsScope();
  NetnsScope(const NetnsScope&) = delete;
  NetnsScope& operator=(const NetnsScope&) = delete;

 private:
  int saved_ = -1;
};

// A veth pair: end a in `ns_a`, end b in `ns_b` (nullptr: this process's own namespace), both up.
class VethPair {
 public:
  VethPair(const NetNamespace* ns_a, const NetNamespace* ns_b);
  ~VethPair();
  VethPair(const VethPair&) = delete;
  VethPair& operator=(const VethPair&) = delete;

  enum class End { A, B };
  [[nodiscard]] const std::string& a() const noexcept { return a_; }
  [[nodiscard]] const std::string& b() const noexcept { return b_; }
  [[nodiscard]] const std::string& name(End e) const noexcept { return e == End::A ? a_ : b_; }

  // `ip link set END up|down` inside its namespace; throws on failure.
  void set_up(End e, bool up) const;
  // `ip link set END ARGS...` inside its namespace (mtu, address, ...); throws on failure.
  void set(End e, const std::vector<std::string>& args) const;
  // Deletes the pair (both ends go), and makes it again with the same names, both up.
  void remove();
  void create();
  // Waits until both ends are operationally up (`state UP`): the kernel's link watch attaches the
  // transmit queue only then, some time after `ip link set up`, and drops what is sent before.
  // create() waits; after set_up(e, true) a test waits with this. Throws after `timeout`.
  void wait_up(std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) const;

 private:
  RunResult ip_in(End e, const std::vector<std::string>& args) const;

  const NetNamespace* ns_a_;
  const NetNamespace* ns_b_;
  std::string a_;
  std::string b_;
  bool exists_ = false;
};

// A forked child that runs `body` (its return value is the exit status), inside `ns` when given.
// What the child writes to `out` (a pipe) the parent reads with read_line(). The child is killed
// when this object goes, and when the parent dies first (PR_SET_PDEATHSIG).
class ChildProcess {
 public:
  ChildProcess(const NetNamespace* ns, const std::function<int(int out)>& body);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // The next line the child wrote, nullopt when none came in time or it closed the pipe.
  std::optional<std::string> read_line(std::chrono::milliseconds timeout);
  // The exit status once the child ended within `timeout`, else nullopt.
  std::optional<int> wait(std::chrono::milliseconds timeout);
  [[nodiscard]] pid_t pid() const noexcept { return pid_; }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  PipeLines lines_;
  std::optional<int> status_;
};

// Writes `line` and a newline to `fd` (for ChildProcess bodies).
void write_line(int fd, const std::string& line);

}  // namespace drivegate::test
