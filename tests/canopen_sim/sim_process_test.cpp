// The drivegate-sim binary as a child process: its ready line, SDO answers on the udp-multicast bus
// seen through the gateway's own UdpMulticastTransport, the stdin control channel, SIGTERM, and
// what it says about configs it cannot run. Each test uses its own UDP port.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "adapters/canopen/transport/udp_multicast_transport.hpp"
#include "tests/canopen_sim/sim_test_support.hpp"
#include "tests/support/pipe_lines.hpp"

extern char** environ;

namespace drivegate::canopen::sim::test {
namespace {

using Clock = std::chrono::steady_clock;

// Ports 12000..15999: four per process id, below the transport tests' block and the ephemeral range.
std::uint16_t test_port(unsigned slot) {
  return static_cast<std::uint16_t>(12000 + (static_cast<unsigned>(::getpid()) % 1000) * 4 + slot);
}

std::filesystem::path write_config(const std::string& name, const std::string& yaml) {
  const auto path = std::filesystem::temp_directory_path() / ("drivegate-sim-test-" + std::to_string(::getpid()) + "-" + name + ".yaml");
  std::ofstream(path) << yaml;
  return path;
}

std::string udp_config(std::uint16_t port) {
  return R"(
gateway: { name: sim-test }
buses:
  - name: can0
    type: canopen
    cycle_time: 4ms
    options: { transport: udp-multicast, interface: 127.0.0.1, port: )" +
         std::to_string(port) + R"( }
axes:
  - { name: a, bus: can0, address: 5, device: kollmorgen-akd, mechanics: { encoder_counts_per_rev: 1048576 } }
)";
}

// The simulator with pipes on stdin, stdout and stderr.
class SimProcess {
 public:
  explicit SimProcess(const std::filesystem::path& config) {
    int in[2];
    int out[2];
    int err[2];
    if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0 || ::pipe2(err, O_CLOEXEC) != 0) {
      ADD_FAILURE() << "pipe2 failed";
      return;
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in[0], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
    const std::string exe = DRIVEGATE_SIM_EXE;
    const std::string file = config.string();
    std::vector<char*> argv{const_cast<char*>(exe.c_str()), const_cast<char*>(file.c_str()), nullptr};
    if (posix_spawn(&pid_, exe.c_str(), &actions, nullptr, argv.data(), environ) != 0) {
      ADD_FAILURE() << "cannot start " << exe;
      pid_ = -1;
    }
    posix_spawn_file_actions_destroy(&actions);
    ::close(in[0]);
    ::close(out[1]);
    ::close(err[1]);
    stdin_ = in[1];
    stdout_ = out[0];
    stderr_ = err[0];
  }
  ~SimProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    for (int fd : {stdin_, stdout_, stderr_}) {
      if (fd >= 0) ::close(fd);
    }
  }
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  // The next stdout line, waiting at most `timeout`.
  std::optional<std::string> line(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    return out_lines_.next(stdout_, timeout);
  }
  std::string error_text() {
    std::string all;
    while (const auto l = err_lines_.next(stderr_, std::chrono::milliseconds(2000))) all += *l + "\n";
    return all;
  }
  std::optional<std::string> command(const std::string& c) {
    const std::string l = c + "\n";
    if (::write(stdin_, l.data(), l.size()) != static_cast<ssize_t>(l.size())) return std::nullopt;
    return line();
  }
  // Exit status after SIGTERM (or after it ended by itself), -1 when it did not end in 5 s.
  int stop(bool signal = true) {
    if (signal) ::kill(pid_, SIGTERM);
    for (const auto end = Clock::now() + std::chrono::seconds(5); Clock::now() < end;) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      ::poll(nullptr, 0, 10);
    }
    return -1;
  }

 private:
  pid_t pid_ = -1;
  int stdin_ = -1;
  int stdout_ = -1;
  int stderr_ = -1;
  drivegate::test::PipeLines out_lines_;
  drivegate::test::PipeLines err_lines_;
};

core::TimePoint now() { return core::SteadyClock{}.now(); }

// The first frame on `id` within `timeout`, waiting on the transport's descriptor.
std::optional<CanFrame> receive_on(Transport& t, std::uint32_t id, std::chrono::milliseconds timeout) {
  std::array<CanFrame, 16> buf{};
  for (const auto end = Clock::now() + timeout; Clock::now() < end;) {
    pollfd p{t.wait_fd(), POLLIN, 0};
    ::poll(&p, 1, 20);
    const auto n = t.receive(buf, now());
    for (std::size_t i = 0; i < n; ++i) {
      if (buf[i].id == id) return buf[i];
    }
  }
  return std::nullopt;
}

class SimProcessTest : public ::testing::Test {
 protected:
  SimProcessTest()
      : port_(test_port(0)),
        config_(write_config("udp", udp_config(port_))),
        sim_(config_),
        gateway_(UdpMulticastOptions{.port = port_, .interface_address = "127.0.0.1"}) {}
  ~SimProcessTest() override { std::filesystem::remove(config_); }

  // Reads 1000h from node 5; the reply frame, if one came.
  std::optional<CanFrame> read_device_type(std::chrono::milliseconds timeout = std::chrono::seconds(2)) {
    EXPECT_EQ(gateway_.send(make_frame(0x605, sdo_upload_request({0x1000, 0})), now()), SendResult::Sent);
    return receive_on(gateway_, 0x585, timeout);
  }

  std::uint16_t port_;
  std::filesystem::path config_;
  SimProcess sim_;
  UdpMulticastTransport gateway_;
};

TEST_F(SimProcessTest, AnswersSdoOnTheUdpBusAndTakesCommands) {
  const auto ready = sim_.line();
  ASSERT_TRUE(ready) << sim_.error_text();
  EXPECT_EQ(*ready, "drivegate-sim: 1 nodes on udp-multicast 239.74.163.2:" + std::to_string(port_));
  gateway_.open();

  auto reply = read_device_type();
  ASSERT_TRUE(reply);
  EXPECT_TRUE(is_frame(*reply, 0x585, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}));

  const auto status = sim_.command("status");
  ASSERT_TRUE(status);
  EXPECT_EQ(status->rfind("status: can0:5 akd nmt=pre-operational state=switch_on_disabled fault=0x0000", 0), 0U)
      << *status;

  EXPECT_EQ(sim_.command("power-off 5"), "ok power-off node 5");
  EXPECT_FALSE(read_device_type(std::chrono::milliseconds(300)));
  EXPECT_EQ(sim_.command("status").value_or("").find("can0:5 akd off"), 8U);
  EXPECT_EQ(sim_.command("power-on 5"), "ok power-on node 5");
  const auto boot_up = receive_on(gateway_, 0x705, std::chrono::seconds(2));
  ASSERT_TRUE(boot_up);
  EXPECT_TRUE(is_frame(*boot_up, 0x705, {0x00}));

  EXPECT_EQ(sim_.command("fault 5 0x4310"), "ok fault node 5 0x4310");
  const auto emcy = receive_on(gateway_, 0x85, std::chrono::seconds(2));
  ASSERT_TRUE(emcy);
  EXPECT_TRUE(is_frame(*emcy, 0x85, {0x10, 0x43, 0x09, 0x01, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(sim_.command("clear can0:5"), "ok clear node 5");

  EXPECT_EQ(sim_.command("silent 5 on"), "ok silent node 5 on");
  EXPECT_FALSE(read_device_type(std::chrono::milliseconds(300)));
  EXPECT_EQ(sim_.command("silent 5 off"), "ok silent node 5 off");
  EXPECT_TRUE(read_device_type());

  // An injected SDO abort answers the next request for the object; then it reads normally again.
  EXPECT_EQ(sim_.command("abort 5 0x1000 0x08000022"), "ok abort node 5");
  reply = read_device_type();
  ASSERT_TRUE(reply);
  EXPECT_TRUE(is_frame(*reply, 0x585, {0x80, 0x00, 0x10, 0x00, 0x22, 0x00, 0x00, 0x08}));
  EXPECT_TRUE(read_device_type());
  // A corrupted answer arrives with the wrong length.
  EXPECT_EQ(sim_.command("corrupt 5 1 dlc"), "ok corrupt node 5");
  reply = read_device_type();
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->dlc, 7);
  EXPECT_EQ(sim_.command("abort 5 0x1000").value_or("").rfind("error: abort takes", 0), 0U);
  EXPECT_EQ(sim_.command("corrupt 5 0").value_or("").rfind("error: corrupt takes", 0), 0U);

  EXPECT_EQ(sim_.command("launch 5").value_or("").rfind("error: unknown command \"launch\"", 0), 0U);
  EXPECT_EQ(sim_.command("power-off 9"), "error: no simulated node 9");
  EXPECT_EQ(sim_.command("silent 5 maybe").value_or("").rfind("error:", 0), 0U);
  EXPECT_EQ(sim_.command("fault 5 0x10000").value_or("").rfind("error:", 0), 0U);

  EXPECT_EQ(sim_.stop(), 0);
}

TEST(SimProcess, RefusesConfigsItCannotRun) {
  const auto sim_only = write_config("simbus", R"(
gateway: { name: sim-test }
buses:
  - { name: sim0, type: sim, cycle_time: 1ms }
axes:
  - { name: a, bus: sim0, address: 1, device: generic-cia402, mechanics: { encoder_counts_per_rev: 10000 } }
)");
  SimProcess no_bus(sim_only);
  EXPECT_EQ(no_bus.stop(false), 2);
  EXPECT_NE(no_bus.error_text().find("has no canopen bus on udp-multicast"), std::string::npos);
  std::filesystem::remove(sim_only);

  SimProcess missing(std::filesystem::temp_directory_path() / "drivegate-sim-test-no-such-file.yaml");
  EXPECT_EQ(missing.stop(false), 1);
  EXPECT_NE(missing.error_text().find("drivegate-sim: "), std::string::npos);
}

}  // namespace
}  // namespace drivegate::canopen::sim::test
