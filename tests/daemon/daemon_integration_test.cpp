// End-to-end tests with the real drivegated binary on config/demo.yaml (simulated drives) and a
// DDS client, each test on its own DDS domain/namespace so they run in parallel.
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <limits>

#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using namespace std::chrono_literals;

namespace {

constexpr auto kDiscovery = 15s;  // DDS discovery plus daemon start-up, generous for loaded CI machines

client::CommandRequest request(const std::string& axis, const std::string& kind) {
  client::CommandRequest r;
  r.axis = axis;
  r.kind = kind;
  return r;
}

bool has_event(client::Client& c, std::uint64_t& cursor, const std::string& axis, const std::string& kind,
               std::vector<client::AxisEvent>& seen) {
  for (auto& e : c.events_since(cursor)) seen.push_back(e);
  for (const auto& e : seen)
    if (e.axis == axis && e.kind == kind) return true;
  return false;
}

struct Gateway {
  Gateway(const std::string& name, const test::DdsIsolation& dds)
      : config(test::write_demo_config(name, dds)), process(config, notify.path()) {}
  std::string config;
  test::NotifySocket notify;
  test::DaemonProcess process;
};

}  // namespace

TEST(DaemonIntegration, DemoAxesEndToEnd) {
  const auto dds = test::unique_dds("e2e");
  Gateway gw("itest", dds);
  ASSERT_TRUE(gw.notify.wait_for("READY=1", kDiscovery)) << gw.process.log();

  client::Client c(client::options_for(dds.domain, dds.ns, "itest-client"));
  ASSERT_TRUE(c.wait_until([&] { return c.state("x") && c.state("spindle") && c.state("turntable"); }, kDiscovery))
      << gw.process.log();
  std::uint64_t cursor = 0;
  std::vector<client::AxisEvent> events;

  // Everything starts disabled: nothing moves unless a client asks.
  for (const auto& s : c.states()) EXPECT_NE(s.state, "operation_enabled") << s.axis;
  std::printf("drivegated resident memory with the demo config: %ld KiB\n", gw.process.rss_kib());

  // Enable and move x to a position: Completed, and the state shows the target reached there.
  auto r = c.send(request("x", "enable"), true, 5s);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  auto mv = request("x", "move");
  mv.position = 25;
  r = c.send(mv, true, 20s);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  ASSERT_TRUE(c.wait_until([&] {
    const auto s = c.state("x");
    return s && s->target_reached && std::fabs(s->position - 25) < 0.01 && s->state == "operation_enabled";
  }, 3s));

  // A NaN target and an unknown axis are rejected with reasons.
  mv.position = std::numeric_limits<double>::quiet_NaN();
  r = c.send(mv, true, 5s);
  EXPECT_EQ(r.outcome, client::Outcome::Rejected);
  EXPECT_NE(r.reason.find("NaN"), std::string::npos) << r.reason;
  auto unknown = request("no_such_axis", "enable");
  unknown.gateway = "itest";
  r = c.send(unknown, true, 5s);
  EXPECT_EQ(r.outcome, client::Outcome::Rejected);
  EXPECT_NE(r.reason.find("no_such_axis"), std::string::npos) << r.reason;

  // Jog the spindle in velocity mode, then go silent: the command timeout stops it (demo.yaml:
  // timeout_stop: halt, so it ramps to standstill and stays enabled).
  r = c.send(request("spindle", "enable"), true, 5s);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  auto jog = request("spindle", "velocity");
  jog.velocity = 2;
  // The jog's final reply comes when the run ends: here the command timeout ends it.
  r = c.send(jog, true, 10s);
  ASSERT_EQ(r.outcome, client::Outcome::Failed) << r.reason;
  EXPECT_NE(r.reason.find("command timeout 250 ms"), std::string::npos) << r.reason;
  ASSERT_TRUE(has_event(c, cursor, "spindle", "command_timeout", events) ||
              c.wait_until([&] { return has_event(c, cursor, "spindle", "command_timeout", events); }, 5s));
  ASSERT_TRUE(c.wait_until([&] {
    const auto s = c.state("spindle");
    return s && std::fabs(s->velocity) < 0.01 && s->state == "operation_enabled";
  }, 5s));

  // Home the turntable.
  r = c.send(request("turntable", "enable"), true, 5s);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  r = c.send(request("turntable", "home"), true, 30s);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  ASSERT_TRUE(c.wait_until([&] { const auto s = c.state("turntable"); return s && s->homed; }, 3s));

  // SIGTERM: every axis ends disabled, STOPPING is announced, the exit code is 0.
  const auto rc = gw.process.terminate(SIGTERM, 20s);
  ASSERT_TRUE(rc.has_value()) << gw.process.log();
  EXPECT_EQ(*rc, 0) << gw.process.log();
  EXPECT_TRUE(gw.notify.wait_for("STOPPING=1", 1s));
  for (const auto& s : c.states())
    EXPECT_EQ(s.state, "switch_on_disabled")
        << s.axis << " ended in " << s.state << "\n" << gw.process.log();
}

TEST(DaemonIntegration, TwoGatewaysShareADomain) {
  const auto dds = test::unique_dds("pair");
  Gateway a("cell_a", dds);
  Gateway b("cell_b", dds);
  ASSERT_TRUE(a.notify.wait_for("READY=1", kDiscovery)) << a.process.log();
  ASSERT_TRUE(b.notify.wait_for("READY=1", kDiscovery)) << b.process.log();

  client::Client c(client::options_for(dds.domain, dds.ns, "pair-client"));
  ASSERT_TRUE(c.wait_until([&] { return c.gateways().size() == 2; }, kDiscovery));
  for (const auto& g : c.gateways()) EXPECT_FALSE(g.axes.empty()) << g.name;
  ASSERT_TRUE(c.wait_until([&] { return c.state("x", "cell_a") && c.state("x", "cell_b"); }, kDiscovery));

  // The same demo axes on both: a command names its gateway and reaches only that one.
  auto en = request("x", "enable");
  en.gateway = "cell_b";
  const auto r = c.send(en, true, 5s);
  ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason;
  EXPECT_EQ(r.gateway, "cell_b");
  ASSERT_TRUE(c.wait_until([&] { auto s = c.state("x", "cell_b"); return s && s->state == "operation_enabled"; }, 3s));
  EXPECT_NE(c.state("x", "cell_a")->state, "operation_enabled");

  // Each gateway reports that the other claims the same axis names.
  EXPECT_TRUE(c.wait_until([&] {
    std::uint64_t cur = 0;
    for (const auto& e : c.events_since(cur))
      if (e.kind == "warning" && e.text.find("cell_a") != std::string::npos &&
          e.text.find("cell_b") != std::string::npos)
        return true;
    return false;
  }, 10s));

  EXPECT_EQ(a.process.terminate(SIGTERM, 20s), 0);
  EXPECT_EQ(b.process.terminate(SIGTERM, 20s), 0);
}
