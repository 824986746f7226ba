// Signals a service can receive, against the real drivegated on the demo configuration (sim axes and
// the simulated CANopen bus): none may leave an axis moving (DESIGN.md §4 safety rules).
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using namespace std::chrono_literals;

namespace {

constexpr auto kDiscovery = 15s;

client::CommandRequest request(const std::string& axis, const std::string& kind) {
  client::CommandRequest r;
  r.axis = axis;
  r.kind = kind;
  return r;
}

// A daemon on the demo configuration with x and the CANopen akd enabled and in a long move.
class Signals : public ::testing::Test {
 protected:
  void start(const std::string& tag) {
    dds_ = test::unique_dds(tag);
    config_ = test::write_demo_config("sig_" + tag, dds_);
    process_ = std::make_unique<test::DaemonProcess>(config_, notify_.path());
    ASSERT_TRUE(notify_.wait_for("READY=1", kDiscovery)) << process_->log();
    client_ = std::make_unique<client::Client>(client::options_for(dds_.domain, dds_.ns, "sig-client"));
    // Every axis of the configuration operational, not only the two that move: an axis still
    // configuring when the signal arrives ends with no drive state at all, which the orderly-stop
    // check below would take for an axis left enabled (the demo's EtherCAT DC drive takes longest).
    std::vector<std::string> axes;
    for (const auto& a : YAML::LoadFile(config_)["axes"]) axes.push_back(a["name"].as<std::string>());
    ASSERT_TRUE(client_->wait_until([&] {
      return std::all_of(axes.begin(), axes.end(), [&](const std::string& name) {
        const auto s = client_->state(name);
        return s && s->link == "operational";
      });
    }, 2 * kDiscovery)) << process_->log();
  }

  void start_moving() {
    for (const char* axis : {"x", "akd"}) {
      const auto r = client_->send(request(axis, "enable"), true, 10s);
      ASSERT_EQ(r.outcome, client::Outcome::Completed) << axis << ": " << r.reason << process_->log();
      auto mv = request(axis, "move");
      mv.position = 300;
      mv.velocity = 10;  // 30 s of travel: still moving when the signal arrives
      const auto m = client_->send(mv, false, 10s);
      ASSERT_EQ(m.outcome, client::Outcome::Accepted) << axis << ": " << m.reason;
    }
    ASSERT_TRUE(client_->wait_until([&] {
      return std::fabs(client_->state("x")->velocity) > 5 && std::fabs(client_->state("akd")->velocity) > 5;
    }, 5s)) << process_->log();
  }

  bool moving(const std::string& axis) const {
    const auto s = client_->state(axis);
    return s && s->state == "operation_enabled" && std::fabs(s->velocity) > 5;
  }

  // The axes are still moving a while later: the daemon took the signal without stopping anything.
  void expect_still_moving() {
    const auto seq = client_->state("x")->seq;
    ASSERT_TRUE(client_->wait_until([&] { return client_->state("x")->seq > seq + 5; }, 3s)) << process_->log();
    EXPECT_TRUE(moving("x")) << process_->log();
    EXPECT_TRUE(moving("akd")) << process_->log();
    EXPECT_TRUE(process_->running());
  }

  // Exit 0 and every axis ends disabled, the last published states say so.
  void expect_orderly_stop(std::optional<int> rc) {
    ASSERT_TRUE(rc.has_value()) << process_->log();
    EXPECT_EQ(*rc, 0) << process_->log();
    // The daemon wrote its last states before it exited, but this client takes them in on its own
    // DDS threads, which a loaded machine may run well after the exit: wait for them to arrive.
    const auto all_disabled = [&] {
      const auto states = client_->states();
      return !states.empty() && std::all_of(states.begin(), states.end(), [](const client::AxisState& s) {
        return s.state == "switch_on_disabled";
      });
    };
    client_->wait_until(all_disabled, 5s);
    for (const auto& s : client_->states())
      EXPECT_EQ(s.state, "switch_on_disabled") << s.axis << " ended in " << s.state << "\n" << process_->log();
    EXPECT_NE(process_->log().find("2 axes quick-stopped"), std::string::npos) << process_->log();
  }

  test::DdsIsolation dds_{};
  std::string config_;
  test::NotifySocket notify_;
  std::unique_ptr<test::DaemonProcess> process_;
  std::unique_ptr<client::Client> client_;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// SIGHUP re-reads and checks the file and says what a restart would change; nothing restarts and
// nothing stops.
TEST_F(Signals, HangupChecksTheFileAndSaysWhatWouldChange) {
  ASSERT_NO_FATAL_FAILURE(start("hup"));
  ASSERT_NO_FATAL_FAILURE(start_moving());
  const std::string original = read_file(config_);

  ASSERT_EQ(kill(process_->pid(), SIGHUP), 0);
  ASSERT_TRUE(notify_.wait_for("RELOADING=1", 5s));
  ASSERT_NO_FATAL_FAILURE(expect_still_moving());
  // RELOADING=1 goes out before the file is read; the verdict reaches the log file afterwards.
  EXPECT_TRUE(client_->wait_until(
      [&] { return process_->log().find("re-read and checked: no changes") != std::string::npos; }, 5s))
      << process_->log();

  // x's velocity limit in demo.yaml is 200 mm/s.
  const std::string changed = std::regex_replace(original, std::regex("max_velocity: 200"), "max_velocity: 250",
                                                 std::regex_constants::format_first_only);
  ASSERT_NE(changed, original);
  std::ofstream(config_) << changed;
  ASSERT_EQ(kill(process_->pid(), SIGHUP), 0);
  ASSERT_TRUE(client_->wait_until([&] { return process_->log().find("would change") != std::string::npos; }, 5s))
      << process_->log();
  EXPECT_NE(process_->log().find("would change axis x: max velocity: 200 mm/s -> 250 mm/s"), std::string::npos)
      << process_->log();

  std::ofstream(config_) << original << "  - name: broken\n";
  ASSERT_EQ(kill(process_->pid(), SIGHUP), 0);
  ASSERT_TRUE(client_->wait_until(
      [&] { return process_->log().find("has errors; the running configuration stays") != std::string::npos; }, 5s))
      << process_->log();
  ASSERT_NO_FATAL_FAILURE(expect_still_moving());
  expect_orderly_stop(process_->terminate(SIGTERM, 20s));
}

// SIGPIPE is ignored; terminal stop signals must not freeze the cycle threads with axes moving.
TEST_F(Signals, PipeAndTerminalStopsAreIgnored) {
  ASSERT_NO_FATAL_FAILURE(start("pipe"));
  ASSERT_NO_FATAL_FAILURE(start_moving());
  for (int sig : {SIGPIPE, SIGTSTP, SIGTTIN, SIGTTOU}) ASSERT_EQ(kill(process_->pid(), sig), 0);
  ASSERT_NO_FATAL_FAILURE(expect_still_moving());
  EXPECT_TRUE(client_->wait_until([&] { return process_->log().find("SIGTSTP ignored") != std::string::npos; }, 5s))
      << process_->log();
  expect_orderly_stop(process_->terminate(SIGTERM, 20s));
}

// GNU timeout and a kill of the process group deliver SIGTERM twice within milliseconds: that is
// one request to stop, not "exit at once".
TEST_F(Signals, ATermDeliveredTwiceAtOnceStillStopsTheAxes) {
  ASSERT_NO_FATAL_FAILURE(start("twice"));
  ASSERT_NO_FATAL_FAILURE(start_moving());
  ASSERT_EQ(kill(process_->pid(), SIGTERM), 0);
  // Two deliveries before the daemon reads the first merge into one pending signal; the case that
  // matters is the second arriving once the stop has begun.
  ASSERT_TRUE(client_->wait_until([&] { return process_->log().find("SIGTERM received") != std::string::npos; }, 5s))
      << process_->log();
  expect_orderly_stop(process_->terminate(SIGTERM, 20s));
  EXPECT_NE(process_->log().find("SIGTERM ignored"), std::string::npos) << process_->log();
}

// Every other signal whose default action would end the process runs the orderly stop.
class StopSignals : public Signals, public ::testing::WithParamInterface<int> {};

TEST_P(StopSignals, StopAndDisableEveryAxisBeforeExiting) {
  const int sig = GetParam();
  ASSERT_NO_FATAL_FAILURE(start("stop" + std::to_string(sig)));
  ASSERT_NO_FATAL_FAILURE(start_moving());
  expect_orderly_stop(process_->terminate(sig, 20s));
}

INSTANTIATE_TEST_SUITE_P(Daemon, StopSignals, ::testing::Values(SIGINT, SIGUSR1, SIGALRM, SIGRTMIN + 3),
                         [](const ::testing::TestParamInfo<int>& p) { return "signal" + std::to_string(p.param); });

}  // namespace
