// Two masters on one set of drives: a second instance of a gateway (same name, same DDS domain)
// and a second gateway on the same bus interface are refused, loudly, by the real drivegated.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using namespace std::chrono_literals;

namespace {

constexpr auto kStartUp = 15s;

bool has_event(client::Client& c, const std::string& kind, const std::string& text, std::chrono::milliseconds timeout) {
  std::uint64_t cursor = 0;
  std::vector<client::AxisEvent> seen;
  return c.wait_until(
      [&] {
        for (auto& e : c.events_since(cursor)) seen.push_back(e);
        for (const auto& e : seen)
          if (e.kind == kind && e.text.find(text) != std::string::npos) return true;
        return false;
      },
      timeout);
}

// A second drivegated with the same gateway name on the same domain refuses to start before it
// opens any bus; the first one reports the attempt and goes on.
TEST(DuplicateGateway, ASecondInstanceRefusesToStart) {
  const auto dds = test::unique_dds("dup1");
  test::NotifySocket notify_a;
  test::DaemonProcess a(test::write_demo_config("dupgw", dds), notify_a.path());
  ASSERT_TRUE(notify_a.wait_for("READY=1", kStartUp)) << a.log();
  client::Client c(client::options_for(dds.domain, dds.ns, "dup-client"));
  std::uint64_t cursor = 0;
  (void)c.events_since(cursor);  // the event reader matches the gateway before the second one starts

  test::NotifySocket notify_b;
  // A generous start-up check: this test is about the refusal, on a machine that runs other tests.
  test::DaemonProcess b(test::write_demo_config("dupgw", dds,
                                                [](YAML::Node& root) { root["gateway"]["dds"]["duplicate_check"] = "5s"; }),
                        notify_b.path());
  const auto rc = b.wait_exit(kStartUp);
  ASSERT_TRUE(rc.has_value()) << b.log();
  EXPECT_EQ(*rc, 1) << b.log();
  EXPECT_NE(b.log().find("refusing to start: another drivegated runs as gateway 'dupgw'"), std::string::npos)
      << b.log();
  EXPECT_NE(b.log().find("pid " + std::to_string(a.pid())), std::string::npos) << b.log();
  EXPECT_EQ(b.log().find("bus sim0:"), std::string::npos) << "a bus was opened:\n" << b.log();
  EXPECT_FALSE(notify_b.wait_for("READY=1", 10ms));

  EXPECT_TRUE(has_event(c, "duplicate_gateway", "that one started later and must stop", kStartUp)) << a.log();
  EXPECT_NE(a.log().find("another drivegated runs as gateway 'dupgw'"), std::string::npos) << a.log();
  EXPECT_TRUE(a.running());
  EXPECT_EQ(a.terminate(SIGTERM, 20s), 0);
}

// One that did not see the first within its start-up check (here 1 ms) finds it while running:
// both report it, and the later one stops its axes and exits 1.
TEST(DuplicateGateway, OneThatAppearsWhileRunningIsStopped) {
  const auto dds = test::unique_dds("dup2");
  test::NotifySocket notify_a;
  test::DaemonProcess a(test::write_demo_config("dupgw2", dds), notify_a.path());
  ASSERT_TRUE(notify_a.wait_for("READY=1", kStartUp)) << a.log();

  const auto quick = test::write_demo_config("dupgw2", dds,
                                             [](YAML::Node& root) { root["gateway"]["dds"]["duplicate_check"] = "1ms"; });
  test::NotifySocket notify_b;
  test::DaemonProcess b(quick, notify_b.path());
  const auto rc = b.wait_exit(kStartUp);
  ASSERT_TRUE(rc.has_value()) << b.log();
  EXPECT_EQ(*rc, 1) << b.log();
  // Seen at once or while running: either way it never drives the axes alongside the first.
  const std::string log = b.log();
  EXPECT_TRUE(log.find("started first: stopping and disabling every axis") != std::string::npos ||
              log.find("refusing to start") != std::string::npos)
      << log;
  EXPECT_TRUE(a.running());
  EXPECT_NE(a.log().find("that one started later and must stop"), std::string::npos) << a.log();
  EXPECT_EQ(a.terminate(SIGTERM, 20s), 0);
}

// Another gateway (another name) on the same CAN bus of this machine is refused with the process
// that drives it.
TEST(DuplicateGateway, TwoGatewaysOnOneBusInterfaceAreRefused) {
  const auto dds = test::unique_dds("dup3");
  const auto pid = static_cast<unsigned>(::getpid());
  const std::string group = "239.74." + std::to_string((pid >> 8) % 256) + "." + std::to_string(pid % 256);
  const auto config = [&](const std::string& name) {
    return test::write_config_text(name, "gateway: { name: " + name + ", dds: { domain: " + std::to_string(dds.domain) +
                                             ", namespace: " + dds.ns + " } }\n"
                                             "buses:\n"
                                             "  - { name: can0, type: canopen, cycle_time: 4ms,\n"
                                             "      options: { transport: udp-multicast, group: " + group +
                                             ", port: 43113, bitrate: 1000000 } }\n"
                                             "axes:\n"
                                             "  - { name: akd, bus: can0, address: 1, device: kollmorgen-akd, unit: mm, "
                                             "mechanics: { feed: 5 } }\n");
  };
  test::NotifySocket notify_a;
  test::DaemonProcess a(config("cell_a"), notify_a.path());
  ASSERT_TRUE(notify_a.wait_for("READY=1", kStartUp)) << a.log();
  test::NotifySocket notify_b;
  test::DaemonProcess b(config("cell_b"), notify_b.path());
  const auto rc = b.wait_exit(kStartUp);
  ASSERT_TRUE(rc.has_value()) << b.log();
  EXPECT_EQ(*rc, 1) << b.log();
  EXPECT_NE(b.log().find("canopen udp-multicast " + group + ":43113 is already driven by process " +
                         std::to_string(a.pid())),
            std::string::npos)
      << b.log();
  EXPECT_TRUE(a.running());
  EXPECT_EQ(a.terminate(SIGTERM, 20s), 0);
}

}  // namespace
