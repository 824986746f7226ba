// DDS Security with real certificates from scripts/make-pki.sh (DESIGN.md §6): who may do what on
// a gateway whose config turns security on. Negative cases wait well past the point where a
// legitimate participant (the positive control, same domain, started at the same time) matched:
// authentication retries every second and announcements come every second.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"
#include "tests/support/run_program.hpp"

using namespace drivegate;
using namespace std::chrono_literals;

namespace {

constexpr auto kStartUp = 20s;
constexpr auto kNothingSeen = 6s;  // > announcement period + handshake retry, with margin

using test::run_program;
using test::RunResult;

class Security : public ::testing::Test {
 protected:
  void SetUp() override {
    dds_ = test::unique_dds("sec");
    pki_ = std::filesystem::temp_directory_path() /
           ("drivegate-pki-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    const RunResult made = run_program({DRIVEGATE_MAKE_PKI, pki_.string(), "--domain", std::to_string(dds_.domain),
                                        "--client", "observer:observer", "--client", "operator:operator",
                                        "--client", "engineer:engineer", "--client", "old:operator:expired",
                                        "--other-ca", "rogue:operator"});
    ASSERT_EQ(made.status, 0) << made.output;
    const std::string gateway_dir = (pki_ / "gateway").string();
    config_ = test::write_demo_config("secure", dds_, [&](YAML::Node& root) {
      root["gateway"]["security"]["dir"] = gateway_dir;
    });
    daemon_ = std::make_unique<test::DaemonProcess>(config_, notify_.path(), "info");
    ASSERT_TRUE(notify_.wait_for("READY=1", kStartUp)) << daemon_->log();
    EXPECT_NE(daemon_->log().find("DDS Security on"), std::string::npos) << daemon_->log();
  }
  void TearDown() override {
    if (daemon_) {
      EXPECT_EQ(daemon_->terminate(SIGTERM, 20s), 0) << daemon_->log();
    }
    std::filesystem::remove_all(pki_);
  }

  client::ClientOptions as(const std::string& who) const {
    auto o = client::options_for(dds_.domain, dds_.ns, "sec-" + who);
    if (!who.empty() && who != "nobody") o.identity = (pki_ / who).string();
    return o;
  }
  // Discovery of the gateway and its axis x.
  static bool sees_gateway(client::Client& c, std::chrono::milliseconds timeout) {
    return c.wait_until([&] { return c.state("x").has_value() && !c.gateways().empty(); }, timeout);
  }
  std::string ctl(const std::string& identity, const std::vector<std::string>& args) const {
    std::vector<std::string> argv{DRIVEGATECTL_PATH, "--domain", std::to_string(dds_.domain), "--namespace", dds_.ns};
    if (!identity.empty()) argv.insert(argv.end(), {"--identity", (pki_ / identity).string()});
    argv.insert(argv.end(), args.begin(), args.end());
    const RunResult r = run_program(argv);
    return std::to_string(r.status) + ":" + r.output;
  }

  test::DdsIsolation dds_{};
  std::filesystem::path pki_;
  std::string config_;
  test::NotifySocket notify_;
  std::unique_ptr<test::DaemonProcess> daemon_;
};

client::CommandRequest request(const std::string& axis, const std::string& kind) {
  client::CommandRequest r;
  r.axis = axis;
  r.kind = kind;
  return r;
}

// operator: commands and set-points, no parameters.
TEST_F(Security, AnOperatorCommandsButMayNotTouchParameters) {
  client::Client op(as("operator"));
  ASSERT_TRUE(sees_gateway(op, kStartUp)) << daemon_->log();
  auto r = op.send(request("x", "enable"), true, 10s);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  auto mv = request("x", "move");
  mv.position = 5;
  r = op.send(mv, true, 20s);
  EXPECT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  client::ParamRequest p;
  p.axis = "x";
  p.index = 0x6064;
  const auto pr = op.param(p, 5s);
  EXPECT_FALSE(pr.ok);
  EXPECT_NE(pr.error.find("access control"), std::string::npos) << pr.error;
  EXPECT_NE(pr.error.find("param_request"), std::string::npos) << pr.error;
}

// engineer: parameters too.
TEST_F(Security, AnEngineerReadsAndWritesParameters) {
  client::Client eng(as("engineer"));
  ASSERT_TRUE(sees_gateway(eng, kStartUp)) << daemon_->log();
  client::ParamRequest p;
  p.axis = "x";
  p.write = true;
  p.index = 0x6081;
  p.value = "12345";
  auto r = eng.param(p, 10s);
  ASSERT_TRUE(r.ok) << r.error;
  p.write = false;
  r = eng.param(p, 10s);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.integer(), 12345);
  EXPECT_EQ(eng.send(request("x", "enable"), true, 10s).outcome, client::Outcome::Completed);
  // The I/O topics are the engineer's (and the gateway serves them: its permissions allow them).
  EXPECT_EQ(eng.io_refusal(), "");
  EXPECT_EQ(daemon_->log().find("I/O topics are not served"), std::string::npos) << daemon_->log();
}

// observer: reads state, cannot create a command writer; drivegatectl says why.
TEST_F(Security, AnObserverReadsStateButCannotCommand) {
  client::Client obs(as("observer"));
  ASSERT_TRUE(sees_gateway(obs, kStartUp)) << daemon_->log();
  EXPECT_EQ(obs.state("x")->state, "switch_on_disabled");
  EXPECT_NE(obs.command_refusal().find("DDS access control refused it"), std::string::npos) << obs.command_refusal();
  const auto r = obs.send(request("x", "enable"), true, 5s);
  EXPECT_EQ(r.outcome, client::Outcome::Denied);
  EXPECT_NE(r.reason.find("axis_command"), std::string::npos) << r.reason;
  const std::string out = ctl("observer", {"enable", "x"});
  EXPECT_EQ(out.rfind("1:", 0), 0u) << out;
  EXPECT_NE(out.find("enable x: denied"), std::string::npos) << out;
  EXPECT_NE(out.find("access control"), std::string::npos) << out;
  const std::string status = ctl("observer", {"status", "x"});
  EXPECT_EQ(status.rfind("0:", 0), 0u) << status;
  EXPECT_NE(status.find("switch_on_disabled"), std::string::npos) << status;
  // The link detail (axis_link) is the observer's to read as well.
  EXPECT_NE(status.find("x: link operational for "), std::string::npos) << status;
  ASSERT_TRUE(obs.wait_until([&] { return obs.link("x").has_value(); }, 5s));
  EXPECT_EQ(obs.link("x")->link, "operational");
  // I/O: the observer reads io_state but may not write outputs.
  EXPECT_NE(obs.io_refusal().find("io_write"), std::string::npos) << obs.io_refusal();
  client::IoWriteRequest w;
  w.gateway = "gw";
  w.slave = "panel";
  w.data = {0x01};
  const auto io = obs.io_write(w, 2s);
  EXPECT_FALSE(io.ok);
  EXPECT_NE(io.error.find("access control"), std::string::npos) << io.error;
  // ...and reads them (the demo's EtherCAT panel, signed not encrypted).
  ASSERT_TRUE(obs.wait_until([&] { return obs.io_state("panel").has_value(); }, 5s));
  EXPECT_EQ(obs.io_state("panel")->inputs.size(), 2U);
}

// No identity, a certificate of another CA, an expired one: nothing to see, nothing to command.
TEST_F(Security, StrangersSeeNothingAndCommandNothing) {
  client::Client control(as("operator"));  // positive control, started with the others
  client::Client plain(as("nobody"));
  client::Client rogue(as("rogue"));
  ASSERT_TRUE(sees_gateway(control, kStartUp)) << daemon_->log();
  std::this_thread::sleep_for(kNothingSeen);  // a time window, not a condition: nothing must happen in it
  for (client::Client* c : {&plain, &rogue}) {
    EXPECT_TRUE(c->gateways().empty()) << c->name();
    EXPECT_TRUE(c->states().empty()) << c->name();
    const auto r = c->send(request("x", "enable"), true, 2s);
    EXPECT_EQ(r.outcome, client::Outcome::NoGateway) << c->name() << ": " << r.reason;
  }
  EXPECT_EQ(control.state("x")->state, "switch_on_disabled");  // nothing reached the axis
  try {
    client::Client expired(as("old"));
    ADD_FAILURE() << "a participant with an expired certificate was created";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not expired"), std::string::npos) << e.what();
  }
  const std::string out = ctl("old", {"status"});
  EXPECT_EQ(out.rfind("1:", 0), 0u) << out;
}

// Security is off in the demo and on in the production example (and so in the systemd deployment,
// which starts from it): with certificates where it expects them, it passes --check-config.
TEST(SecurityConfig, OnInTheProductionExampleOffInTheDemo) {
  const auto pki = std::filesystem::temp_directory_path() / ("drivegate-pki-prod-" + std::to_string(::getpid()));
  const RunResult made = run_program({DRIVEGATE_MAKE_PKI, pki.string()});
  ASSERT_EQ(made.status, 0) << made.output;
  std::ifstream in(DRIVEGATE_PRODUCTION_CONFIG);
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string installed = "/etc/drivegate/pki/gateway";
  ASSERT_NE(yaml.find("dir: " + installed), std::string::npos);
  yaml.replace(yaml.find(installed), installed.size(), (pki / "gateway").string());
  const std::string file = test::write_config_text("production", yaml);
  RunResult r = run_program({DRIVEGATED_PATH, "--check-config", file});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("dds security:    on: certificate " + (pki / "gateway" / "cert.pem").string()), std::string::npos)
      << r.output;
  r = run_program({DRIVEGATED_PATH, "--check-config", DRIVEGATE_DEMO_CONFIG});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("dds security:    off"), std::string::npos) << r.output;
  std::filesystem::remove_all(pki);
}

}  // namespace
