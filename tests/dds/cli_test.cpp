// drivegatectl as a subprocess against an in-process bridge: exit codes, JSON output, reasons.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "daemon/dds_bridge.hpp"
#include "fake_runtime.hpp"

namespace drivegate::dds_test {
namespace {

std::uint32_t test_domain() { return 20U + static_cast<std::uint32_t>(::getpid() % 80); }  // see bridge_client_test

std::string test_namespace() {
  return "dgcli_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

struct CtlRun {
  int status = -1;
  std::string output;  // stdout and stderr
};

CtlRun run_tool(const char* tool, const std::string& args) {
  const std::string cmd = std::string(tool) + " --domain " + std::to_string(test_domain()) +
                          " --namespace " + test_namespace() + " --timeout 10 " + args + " 2>&1";
  CtlRun r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int ws = ::pclose(p);
  r.status = WIFEXITED(ws) ? WEXITSTATUS(ws) : -1;
  return r;
}

daemon::DdsBridgeOptions bridge_options() {
  daemon::DdsBridgeOptions o;
  o.domain = test_domain();
  o.ns = test_namespace();
  o.status_rate_hz = 20;
  return o;
}

CtlRun ctl(const std::string& args) { return run_tool(DRIVEGATECTL_PATH, args); }

class Drivegatectl : public ::testing::Test {
 protected:
  void SetUp() override { bridge_.start(); }
  FakeRuntime rt_{"gw1", {"x", "y"}};
  daemon::DdsBridge bridge_{rt_, bridge_options()};
};

TEST_F(Drivegatectl, MoveCompletesWithJsonResult) {
  const CtlRun r = ctl("--json move x 5 --velocity 2 --relative");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(R"("status":"completed")"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(R"("gateway":"gw1")"), std::string::npos) << r.output;
  ASSERT_EQ(rt_.commands().size(), 1U);
  EXPECT_DOUBLE_EQ(rt_.commands()[0].command.position, 5);
  EXPECT_TRUE(rt_.commands()[0].command.relative);
}

TEST_F(Drivegatectl, UnknownAxisFailsWithTheKnownAxes) {
  const CtlRun r = ctl("enable nope");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("no gateway owns axis 'nope'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("gw1/x"), std::string::npos) << r.output;
}

TEST_F(Drivegatectl, RejectedCommandExitsNonZeroWithTheReason) {
  rt_.set_busy(true);
  const CtlRun r = ctl("reset y");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("busy: the gateway's command queue"), std::string::npos) << r.output;
}

TEST_F(Drivegatectl, ListStatusAndParam) {
  CtlRun r = ctl("--json list");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(R"("name":"y")"), std::string::npos) << r.output;
  r = ctl("status x");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("switch_on_disabled"), std::string::npos) << r.output;
  rt_.set_object(0, 0x6061, 0, -3);
  r = ctl("param get x 6061h:0 --size 1 --signed");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("6061:0 = -3"), std::string::npos) << r.output;
  r = ctl("param set x 0x6081 70000");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(rt_.object(0, 0x6081, 0), 70000);
}

TEST_F(Drivegatectl, ParamByName) {
  daemon::ParameterLookup a83;
  a83.index = 0x2053;
  a83.size = 1;
  rt_.add_name("A83", a83);
  rt_.set_object(0, 0x2053, 0, 9);
  CtlRun r = ctl("param get x A83");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("x A83 (2053:0) = 9"), std::string::npos) << r.output;
  r = ctl("param get x A999");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("param get x A999: no object named 'A999'"), std::string::npos) << r.output;
  // With the h suffix a word that starts with a letter is an index.
  rt_.set_object(0, 0xA83, 0, 5);
  r = ctl("param get x A83h");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("0A83:0 = 5"), std::string::npos) << r.output;
}

TEST_F(Drivegatectl, VelocityStreamsKeepAliveThenStops) {
  const CtlRun r = ctl("velocity y -4.5 --for 0.4");
  EXPECT_EQ(r.status, 0) << r.output;
  const auto cmds = rt_.commands();
  ASSERT_EQ(cmds.size(), 2U) << r.output;
  EXPECT_EQ(cmds[0].command.kind, core::CommandKind::Velocity);
  EXPECT_DOUBLE_EQ(cmds[0].command.velocity, -4.5);
  EXPECT_EQ(cmds[1].command.kind, core::CommandKind::Stop);
  // Set-points are best effort; at 20 Hz for 0.4 s at least one arrives in-process.
  ASSERT_FALSE(rt_.setpoints().empty());
  EXPECT_DOUBLE_EQ(rt_.setpoints().back().second.velocity, -4.5);
}

TEST(DrivegateDemo, RunsTheWholeSequenceAndLeavesAxesDisabled) {
  FakeRuntime rt("demo", {"x", "y", "spindle", "turntable"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  const CtlRun r = run_tool(DRIVEGATE_DEMO_PATH, "--plain --jog-seconds 0.3");
  EXPECT_EQ(r.status, 0) << r.output;
  std::map<core::CommandKind, int> kinds;
  for (const auto& c : rt.commands()) ++kinds[c.command.kind];
  EXPECT_EQ(kinds[core::CommandKind::Enable], 4);
  EXPECT_EQ(kinds[core::CommandKind::Home], 1);
  EXPECT_EQ(kinds[core::CommandKind::Move], 8);
  EXPECT_EQ(kinds[core::CommandKind::Velocity], 1);
  EXPECT_EQ(kinds[core::CommandKind::Stop], 1);
  EXPECT_EQ(kinds[core::CommandKind::Disable], 4);
  EXPECT_EQ(rt.commands().back().command.kind, core::CommandKind::Disable);
}

TEST(DrivegatectlUsage, BadUsageExitsWithTwo) {
  EXPECT_EQ(ctl("move x").status, 2);
  EXPECT_EQ(ctl("move x 1 --bogus 3").status, 2);
  EXPECT_EQ(ctl("frobnicate").status, 2);
  const CtlRun help = ctl("move --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("--relative"), std::string::npos);
}

}  // namespace
}  // namespace drivegate::dds_test
