// `drivegated --scan ethercat:IFACE --write-config F` as a process against drivegate-sim serving a
// line (ESR TrioDrive, a generic I/O slave, a generic CiA 402 drive) on the other end of a veth
// pair in its own network namespace; then `drivegated --check-config F` accepts what it wrote.
// Skipped without root (tests/support/netns.hpp).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/netns.hpp"
#include "tests/support/pipe_lines.hpp"

extern char** environ;

namespace drivegate::ethercat {
namespace {

using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::VethPair;
using namespace std::chrono_literals;

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("drivegate-ecat-scan-test-" + std::to_string(::getpid()) + "-" + name);
}

std::string line_config(const std::string& interface) {
  return R"(gateway: { name: scan-sim }
buses:
  - name: ec0
    type: ethercat
    cycle_time: 1ms
    options: { interface: )" + interface + R"( }
    io:
      - { name: panel, position: 2, vendor_id: 0x99, product_code: 0x1000, inputs: 2, outputs: 1 }
axes:
  - { name: esr, bus: ec0, address: 1, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 } }
  - { name: gen, bus: ec0, address: 3, device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 } }
)";
}

// Runs a command in the caller's network namespace; its output (stdout and stderr) and exit code.
std::pair<int, std::string> run(const std::string& command) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) return {-1, "popen failed"};
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), p)) > 0;) out.append(buf.data(), n);
  const int status = ::pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

TEST(EthercatScanProcess, ScansTheSimulatedLineAndWritesAConfigThatChecks) {
  if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) GTEST_SKIP() << why;
  NetNamespace ns_a;
  NetNamespace ns_b;
  VethPair veth(&ns_a, &ns_b);
  const auto config = temp_file("line.yaml");
  const auto written = temp_file("skeleton.yaml");
  std::ofstream(config) << line_config(veth.a());
  pid_t sim = -1;
  std::array<int, 2> console{-1, -1};
  std::array<int, 2> out{-1, -1};
  {
    const NetnsScope in(ns_b);
    std::string exe = DRIVEGATE_SIM_EXE;
    std::string cfg = config.string();
    std::string flag = "--interface";
    std::string iface = veth.b();
    std::array<char*, 5> argv{exe.data(), cfg.data(), flag.data(), iface.data(), nullptr};
    // stdin from /dev/null would end the console; keep it a pipe the test holds open. stdout is
    // read for the ready line.
    ASSERT_EQ(::pipe2(console.data(), O_CLOEXEC), 0);
    ASSERT_EQ(::pipe2(out.data(), O_CLOEXEC), 0);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, console[0], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    ASSERT_EQ(posix_spawn(&sim, argv[0], &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    ::close(console[0]);
    ::close(out[1]);
  }
  // The simulator answers frames once it printed its ready line (its end is open then).
  drivegate::test::PipeLines lines;
  const auto ready = lines.next(out[0], 20s);
  EXPECT_EQ(ready.value_or("(none)"), "drivegate-sim: 3 slaves on ethercat " + veth.b() + " (bus ec0)");
  std::pair<int, std::string> scan;
  {
    const NetnsScope in(ns_a);
    scan = run(std::string(DRIVEGATED_PATH) + " --scan ethercat:" + veth.a() + " --device-dir " +
               DRIVEGATE_DEVICE_DIR_SOURCE + " --write-config " + written.string());
  }
  ::kill(sim, SIGTERM);
  ::waitpid(sim, nullptr, 0);
  ::close(console[1]);
  ::close(out[0]);
  EXPECT_EQ(scan.first, 0) << scan.second;
  EXPECT_NE(scan.second.find(": 3 devices"), std::string::npos) << scan.second;
  EXPECT_NE(scan.second.find("esr-triodrive"), std::string::npos) << scan.second;
  EXPECT_NE(scan.second.find("generic-cia402"), std::string::npos) << scan.second;
  EXPECT_NE(scan.second.find("wrote " + written.string()), std::string::npos) << scan.second;
  std::ifstream f(written);
  std::stringstream yaml;
  yaml << f.rdbuf();
  EXPECT_NE(yaml.str().find("- { name: io-2, position: 2, vendor_id: 0x00000099, product_code: 0x00001000, inputs: 2, "
                            "outputs: 1 }"),
            std::string::npos)
      << yaml.str();
  // The skeleton names the --device-dir directory in gateway.device_dirs.
  const auto check = run(std::string(DRIVEGATED_PATH) + " --check-config " + written.string());
  EXPECT_EQ(check.first, 0) << check.second << "\n" << yaml.str();
  std::filesystem::remove(config);
  std::filesystem::remove(written);
}

}  // namespace
}  // namespace drivegate::ethercat
