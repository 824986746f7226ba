// Interoperability with a second DDS implementation: the real drivegated (Fast DDS) on a simulated
// bus, driven by cyclone_client (Eclipse Cyclone DDS, C API, types from idlc) over loopback.
// The client reads axis_state, enables, moves and disables the axis on axis_command/command_reply
// and reads an object on param_request/param_reply; see cyclone_client.c.
#include <gtest/gtest.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using namespace std::chrono_literals;

namespace {

constexpr auto kStartup = 15s;         // daemon start-up, generous for loaded CI machines
constexpr int kClientStepTimeoutS = 15;  // cyclone_client --timeout: discovery and each reply
constexpr auto kClientTimeout = 120s;  // the whole client run, a last resort

// DDS domain for this test process: 215..232. Their RTPS ports (7400 + 250 * domain + ...) lie above
// Linux's default ephemeral port range (32768..60999), so no outgoing socket of another program can
// hold them; the daemon tests use 20..99, so the two never share a domain.
std::uint32_t interop_domain() { return 215 + static_cast<std::uint32_t>(getpid()) % 18; }

// Whether the machine has a network interface besides loopback that is up and has an IPv4 address.
// Fast DDS 2.9 (the daemon) then announces only such addresses (never 127.0.0.1) as its locators.
bool has_non_loopback_ipv4() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return false;
  bool found = false;
  for (const ifaddrs* a = list; a != nullptr && !found; a = a->ifa_next)
    found = a->ifa_addr != nullptr && a->ifa_addr->sa_family == AF_INET && (a->ifa_flags & IFF_UP) != 0 &&
            (a->ifa_flags & IFF_LOOPBACK) == 0;
  freeifaddrs(list);
  return found;
}

// Cyclone DDS configuration (CYCLONEDDS_URI) that keeps the client on loopback:
// - no multicast at all (lo has no MULTICAST flag; AllowMulticast false also keeps SPDP off the
//   other interface);
// - participant discovery by unicast to 127.0.0.1 on the well-known SPDP ports of the domain's
//   participant indices 0..MaxAutoParticipantIndex, where Fast DDS participants listen
//   (7410 + 250 * domain + 2 * index);
// - lo selected, and, when the machine has another IPv4 interface that is up, the best such
//   interface too: Fast DDS then announces that interface's address, and Cyclone 0.10 drops a
//   locator it cannot reach through a selected non-loopback interface (it never sends to a
//   non-loopback address through lo), so with lo alone it ignores the daemon ("no unicast address").
//   Datagrams to the machine's own address never leave it: the kernel delivers them on lo.
//   With no such interface (e.g. a network namespace with lo only) Fast DDS announces 127.0.0.1
//   and lo alone is right; Cyclone refuses to select lo twice, so the test decides.
std::string cyclone_config(bool with_host_interface) {
  std::string xml =
      "<CycloneDDS xmlns=\"https://cdds.io/config\"><Domain id=\"any\">"
      "<General><Interfaces><NetworkInterface name=\"lo\" multicast=\"false\"/>";
  if (with_host_interface) xml += "<NetworkInterface autodetermine=\"true\" multicast=\"false\"/>";
  xml +=
      "</Interfaces><AllowMulticast>false</AllowMulticast></General>"
      "<Discovery><ParticipantIndex>none</ParticipantIndex><MaxAutoParticipantIndex>20</MaxAutoParticipantIndex>"
      "<Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>"
      "</Domain></CycloneDDS>";
  return xml;
}

struct ClientRun {
  int status = -1;  // exit status, 128 + signal, or -1 when it had to be killed
  std::string output;
};

// Runs cyclone_client with `args` and CYCLONEDDS_URI = `cyclone_uri`, collecting stdout and stderr.
ClientRun run_client(const std::vector<std::string>& args, const std::string& cyclone_uri) {
  ClientRun run;
  int fds[2];
  if (pipe(fds) != 0) return run;
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) return run;
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    close(fds[0]);
    close(fds[1]);
    setenv("CYCLONEDDS_URI", cyclone_uri.c_str(), 1);
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(CYCLONE_CLIENT_PATH));
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(CYCLONE_CLIENT_PATH, argv.data());
    std::perror("execv " CYCLONE_CLIENT_PATH);
    _exit(127);
  }
  close(fds[1]);
  const auto deadline = std::chrono::steady_clock::now() + kClientTimeout;
  bool killed = false;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      kill(pid, SIGKILL);
      killed = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    char buf[4096];
    const auto n = read(fds[0], buf, sizeof buf);
    if (n <= 0) break;  // EOF: the client has exited (or closed its output)
    run.output.append(buf, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (killed)
    run.status = -1;
  else
    run.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return run;
}

// The number after `key` on the first output line that starts with `line_prefix`, NaN if absent.
double number_after(const std::string& output, const std::string& line_prefix, const std::string& key) {
  std::size_t line = 0;
  while (line < output.size()) {
    const std::size_t end = output.find('\n', line);
    const std::string text = output.substr(line, end == std::string::npos ? std::string::npos : end - line);
    if (text.rfind(line_prefix, 0) == 0) {
      const std::size_t at = text.find(key);
      if (at == std::string::npos) break;
      return std::strtod(text.c_str() + at + key.size(), nullptr);
    }
    if (end == std::string::npos) break;
    line = end + 1;
  }
  return std::nan("");
}

}  // namespace

TEST(Interop, CycloneClientDrivesTheDaemon) {
  const std::uint32_t domain = interop_domain();
  const std::string ns = test::unique_dds("cyclone").ns;
  const std::string gateway = "cyclone-interop";
  // The sim bus part of config/demo.yaml with its axis x (5 mm screw, 26214.4 counts/mm, at 0).
  const std::string yaml = "gateway:\n  name: " + gateway + "\n  dds:\n    domain: " + std::to_string(domain) +
                           "\n    namespace: " + ns +
                           "\n  status_rate_hz: 50\n"
                           "buses:\n"
                           "  - name: sim0\n"
                           "    type: sim\n"
                           "    cycle_time: 1ms\n"
                           "    options:\n"
                           "      acyclic_latency_cycles: 2\n"
                           "axes:\n"
                           "  - name: x\n"
                           "    bus: sim0\n"
                           "    address: 1\n"
                           "    device: sim-servo\n"
                           "    unit: mm\n"
                           "    mechanics: { encoder_counts_per_rev: 131072, gear_ratio: 1, feed: 5, rated_torque: 0 }\n"
                           "    limits: { min_position: -100, max_position: 500, max_velocity: 200, "
                           "max_acceleration: 2000, max_torque: 150 }\n"
                           "    defaults: { mode: profile_position, velocity: 50, acceleration: 500, deceleration: 500 }\n"
                           "    command_timeout: 500ms\n"
                           "    timeout_stop: quick_stop\n"
                           "    enable_step_timeout: 2s\n"
                           "    sim: { start_position: 0, negative_limit_switch: -105, positive_limit_switch: 505 }\n";
  const std::string config = test::write_config_text("cyclone-interop", yaml);
  test::NotifySocket notify;
  test::DaemonProcess daemon(config, notify.path());
  ASSERT_TRUE(notify.wait_for("READY=1", kStartup)) << daemon.log();

  const bool host_interface = has_non_loopback_ipv4();
  const std::string uri = cyclone_config(host_interface);
  std::printf("domain %u, namespace %s; CYCLONEDDS_URI=%s\n", domain, ns.c_str(), uri.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  const ClientRun run = run_client({"--domain", std::to_string(domain), "--namespace", ns, "--gateway", gateway, "--axis",
                                    "x", "--param", "6064:0", "--timeout", std::to_string(kClientStepTimeoutS)},
                                   uri);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0);
  std::printf("cyclone_client exited with %d after %lld ms:\n%s", run.status, static_cast<long long>(ms.count()),
              run.output.c_str());

  EXPECT_EQ(run.status, 0) << run.output << "\n--- drivegated log ---\n" << daemon.log();
  for (const char* step : {"axis_state: gateway=", "command enable id=", "command move id=", "command disable id=",
                           "param read 6064:0 id="})
    EXPECT_NE(run.output.find(step), std::string::npos) << "no line '" << step << "' in\n" << run.output;
  // Both directions decode: doubles and strings of AxisState after the relative move of 1 mm from
  // 0, and the INTEGER32 bytes of ParameterReply: 6064h position actual value, 1 mm = 26214.4 counts.
  const double position = number_after(run.output, "axis_state after move:", "position=");
  EXPECT_NEAR(position, 1.0, 0.01) << run.output;
  const double counts = number_after(run.output, "param read 6064:0", "ok value=");
  EXPECT_NEAR(counts, 26214.4, 262.0) << run.output;
  const std::string log = daemon.log();
  EXPECT_NE(log.find("from 'cyclone-"), std::string::npos) << log;

  ASSERT_TRUE(daemon.running()) << log;
  const auto rc = daemon.terminate(SIGTERM, 20s);
  ASSERT_TRUE(rc.has_value()) << daemon.log();
  EXPECT_EQ(*rc, 0) << daemon.log();
}
