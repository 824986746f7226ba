// gateway_watch: how a drive is made to notice a dead gateway when it lacks the consumer heartbeat
// (1016h), and what happens when it also lacks node guarding (100Ch/100Dh).
#include <gtest/gtest.h>

#include <string>

#include "tests/canopen_bus/bus_harness.hpp"

namespace drivegate::canopen::test {
namespace {

// One drive on node 5 with the device profile `device`, plus an axis `canopen:` line.
std::string one_drive(const std::string& device, const std::string& canopen = "") {
  return std::string("gateway: { name: watch-test, device_dirs: [\"") + DRIVEGATE_TEST_BUS_DEVICE_DIR + "\"] }\n" +
         "buses:\n"
         "  - { name: can0, type: canopen, cycle_time: 4ms, options: { transport: sim, bitrate: 1000000 } }\n"
         "axes:\n"
         "  - name: x\n"
         "    bus: can0\n"
         "    address: 5\n"
         "    device: " + device + "\n" +
         (canopen.empty() ? "" : "    canopen: { " + canopen + " }\n") +
         "    mechanics: { encoder_counts_per_rev: 10000 }\n"
         "    defaults: { velocity: 1000, acceleration: 10000, deceleration: 10000 }\n"
         "    homing: { method: 35 }\n";
}

constexpr const char* kUnwatched =
    "node 5 has neither 1016h (consumer heartbeat) nor 100Ch/100Dh (node guarding): it will not stop by itself if "
    "the gateway dies";

std::size_t count_events(const BusHarness& h, const std::string& text) {
  std::size_t n = 0;
  for (const auto& e : h.events)
    if (std::string(e.text.view()).find(text) != std::string::npos) ++n;
  return n;
}

// The gateway stops (its cycle thread hangs); only the simulated drives run on.
void gateway_dies(BusHarness& h, core::Duration for_how_long) {
  for (auto t = h.now; t < h.now + for_how_long;) {
    t += 4ms;
    h.peer->step(t);
  }
}

TEST(GatewayWatch, DriveWithoutConsumerHeartbeatIsGuardedInstead) {
  BusHarness h(one_drive("generic-no-heartbeat"));
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text() << h.bus->link_detail(0);
  h.run_until([] { return false; }, 1s);
  EXPECT_TRUE(h.all_up()) << h.bus->link_detail(0);
  EXPECT_EQ(h.drive("x").nmt().guard_time(), 100U);  // the bus' guard_time
  EXPECT_GT(h.drive("x").nmt().counters().guard_replies, 5U);  // the master guards it with RTRs
  EXPECT_EQ(h.drive("x").nmt().heartbeat_period(), 0U);       // guarding and heartbeat exclude each other
  EXPECT_EQ(count_events(h, "neither 1016h"), 0U) << h.events_text();
  EXPECT_EQ(h.drive("x").counters().comm_losses, 0U);
  gateway_dies(h, 2s);
  EXPECT_GE(h.drive("x").counters().comm_losses, 1U) << "the drive's life guarding notices the dead gateway";
}

TEST(GatewayWatch, DriveThatCannotWatchRunsWithOneWarning) {
  BusHarness h(one_drive("generic-no-watch"));
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text() << h.bus->link_detail(0);
  h.run_until([] { return false; }, 1s);
  EXPECT_TRUE(h.all_up());
  EXPECT_EQ(count_events(h, kUnwatched), 1U) << h.events_text();
  for (const auto& e : h.events)
    if (std::string(e.text.view()).find(kUnwatched) != std::string::npos) {
      EXPECT_EQ(e.kind, core::EventKind::Warning);
      EXPECT_EQ(e.axis, h.axis("x"));
    }
  // The master still watches the drive's heartbeat.
  EXPECT_GT(h.drive("x").nmt().heartbeat_period(), 0U);
  // A reboot of the drive does not repeat the warning.
  h.drive("x").power_off();
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(0) == core::LinkState::Lost; }, 2s));
  h.drive("x").power_on();
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(0) == core::LinkState::Operational; }, 5s))
      << h.bus->link_detail(0);
  EXPECT_EQ(h.bus->boots(0), 2U);
  EXPECT_EQ(count_events(h, kUnwatched), 1U) << h.events_text();
}

TEST(GatewayWatch, RequiredRefusesADriveThatCannotWatch) {
  BusHarness h(one_drive("generic-no-watch", "gateway_watch: required"));
  h.run_until([] { return false; }, 3s);
  EXPECT_NE(h.bus->link_state(0), core::LinkState::Operational);
  const std::string detail(h.bus->link_detail(0));
  EXPECT_NE(detail.find("node 5 has neither 1016h (consumer heartbeat) nor 100Ch/100Dh (node guarding)"),
            std::string::npos)
      << detail;
  EXPECT_NE(detail.find("gateway_watch: required"), std::string::npos) << detail;
  EXPECT_EQ(count_events(h, kUnwatched), 0U);
}

TEST(GatewayWatch, RequiredTakesGuardingWhenThatIsWhatTheDriveHas) {
  BusHarness h(one_drive("generic-no-heartbeat", "gateway_watch: required"));
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.bus->link_detail(0);
  h.run_until([] { return false; }, 500ms);
  EXPECT_GT(h.drive("x").nmt().counters().guard_replies, 0U);
}

TEST(GatewayWatch, HeartbeatDemandsConsumerHeartbeat) {
  BusHarness h(one_drive("generic-no-heartbeat", "gateway_watch: heartbeat"));
  h.run_until([] { return false; }, 3s);
  EXPECT_NE(h.bus->link_state(0), core::LinkState::Operational);
  const std::string detail(h.bus->link_detail(0));
  EXPECT_NE(detail.find("1016h:01"), std::string::npos) << detail;
}

TEST(GatewayWatch, GenericDriveWithConsumerHeartbeatStillUsesIt) {
  BusHarness h(one_drive("generic-cia402"));
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.bus->link_detail(0);
  EXPECT_NE(h.drive("x").nmt().heartbeat_consumer(), 0U);
  EXPECT_EQ(h.drive("x").nmt().counters().guard_replies, 0U);
  EXPECT_EQ(count_events(h, "neither 1016h"), 0U);
}

// A drive that has 1016h but refuses the gateway's entry in 1016h:01 is guarded when it has
// 100Ch/100Dh, as if it had no 1016h.
class ConsumerEntryRefused : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(ConsumerEntryRefused, FallsBackToGuarding) {
  BusHarness h(one_drive("generic-cia402"));
  // Once the drive is configured (its communication reset has passed), 1016h:01 is still to come.
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(0) == core::LinkState::Configuring; }, 5s));
  h.drive("x").inject_sdo_abort({0x1016, 1}, GetParam());
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text() << h.bus->link_detail(0);
  h.run_until([] { return false; }, 1s);
  EXPECT_TRUE(h.all_up()) << h.bus->link_detail(0);
  EXPECT_EQ(h.bus->boots(0), 1U);
  EXPECT_EQ(h.drive("x").nmt().heartbeat_consumer(), 0U);
  EXPECT_EQ(h.drive("x").nmt().guard_time(), 100U);
  EXPECT_GT(h.drive("x").nmt().counters().guard_replies, 5U);
  EXPECT_EQ(h.drive("x").nmt().heartbeat_period(), 0U);
  EXPECT_EQ(count_events(h, "1016h"), 0U) << h.events_text();
  gateway_dies(h, 2s);
  EXPECT_GE(h.drive("x").counters().comm_losses, 1U) << "the drive's life guarding notices the dead gateway";
}

INSTANTIATE_TEST_SUITE_P(GatewayWatch, ConsumerEntryRefused,
                         ::testing::Values(0x06090030U /* value range */, 0x08000020U /* cannot store */,
                                           0x06010002U /* read-only */));

constexpr const char* kRefusedUnwatched =
    "node 5 refused 1016h:01 (consumer heartbeat, abort 0x06010002) and has no 100Ch/100Dh (node guarding): it will "
    "not stop by itself if the gateway dies";

TEST(GatewayWatch, RefusedConsumerEntryWithoutGuardingRunsWithOneWarning) {
  BusHarness h(one_drive("generic-fixed-heartbeat"));
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text() << h.bus->link_detail(0);
  h.run_until([] { return false; }, 1s);
  EXPECT_TRUE(h.all_up());
  EXPECT_EQ(count_events(h, kRefusedUnwatched), 1U) << h.events_text();
  EXPECT_EQ(count_events(h, "neither 1016h"), 0U) << h.events_text();
  EXPECT_GT(h.drive("x").nmt().heartbeat_period(), 0U);  // the master still watches the drive
  EXPECT_EQ(h.drive("x").nmt().counters().guard_replies, 0U);
}

TEST(GatewayWatch, RequiredRefusesADriveThatRefusesTheConsumerEntryAndHasNoGuarding) {
  BusHarness h(one_drive("generic-fixed-heartbeat", "gateway_watch: required"));
  h.run_until([] { return false; }, 3s);
  EXPECT_NE(h.bus->link_state(0), core::LinkState::Operational);
  const std::string detail(h.bus->link_detail(0));
  EXPECT_NE(detail.find("node 5 refused 1016h:01 (consumer heartbeat) and has no 100Ch/100Dh (node guarding)"),
            std::string::npos)
      << detail;
  EXPECT_NE(detail.find("gateway_watch: required"), std::string::npos) << detail;
  EXPECT_NE(detail.find("abort 0x06010002"), std::string::npos) << detail;
  EXPECT_EQ(count_events(h, kRefusedUnwatched), 0U);
}

TEST(GatewayWatch, HeartbeatDemandsThatTheDriveTakesTheConsumerEntry) {
  BusHarness h(one_drive("generic-fixed-heartbeat", "gateway_watch: heartbeat"));
  h.run_until([] { return false; }, 3s);
  EXPECT_NE(h.bus->link_state(0), core::LinkState::Operational);
  const std::string detail(h.bus->link_detail(0));
  EXPECT_NE(detail.find("write 1016h:01"), std::string::npos) << detail;
  EXPECT_NE(detail.find("0x06010002"), std::string::npos) << detail;
}

TEST(GatewayWatch, BadValueIsAConfigErrorNamingTheChoices) {
  try {
    (void)config::load_plan_from_string(one_drive("generic-no-watch", "gateway_watch: sometimes"), "t.yaml");
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("canopen.gateway_watch: must be one of heartbeat, guarding, required, optional, got "
                        "\"sometimes\""),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace drivegate::canopen::test
