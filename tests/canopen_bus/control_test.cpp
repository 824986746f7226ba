// The gateway never loses control of a drive silently (DESIGN.md §4): objects the CANopen bus
// configured are not writable through parameters, and a drive that stops following its
// controlword is an event, a degraded link, a stop over SDO and a reconfiguration.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/canopen_bus/bus_harness.hpp"

namespace drivegate::canopen::test {
namespace {

using core::AxisState;
using core::CommandKind;
using core::LinkState;
using core::ReplyStatus;

core::ParamReply ask(BusHarness& h, const std::string& axis, bool write, std::uint16_t index, std::uint8_t sub,
                     std::uint8_t size, std::int64_t value = 0) {
  return h.param(axis, write, index, sub, *core::integer_param_type(size, false), std::to_string(value));
}

bool has_event(const BusHarness& h, core::EventKind kind, const std::string& text) {
  for (const auto& e : h.events)
    if (e.kind == kind && std::string(e.text.view()).find(text) != std::string::npos) return true;
  return false;
}

// `param set akd 1400:1 0x80000201` switched the axis' RPDO off and left it enabled and out of
// reach; now the write is refused with the owner, and reading stays possible.
TEST(CanopenControl, WritesToObjectsTheGatewayConfiguredAreRefused) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  const struct {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint8_t size;
    const char* owner;
  } owned[] = {
      {0x1400, 1, 4, "RPDO communication parameter"}, {0x1600, 1, 4, "RPDO mapping"},
      {0x1800, 2, 1, "TPDO communication parameter"}, {0x1A00, 0, 1, "TPDO mapping"},
      {0x1005, 0, 4, "SYNC"},                          {0x1006, 0, 4, "SYNC"},
      {0x1014, 0, 4, "EMCY"},                          {0x1016, 1, 4, "heartbeat consumer"},
      {0x1017, 0, 2, "heartbeat producer"},                     {0x100C, 0, 2, "node guarding"},
      // AKD FBUS.PARAM05 and the feed constant: start-up writes the unit conversion relies on.
      {0x36E9, 0, 4, "start-up write"},                {0x6092, 1, 4, "start-up write"},
  };
  for (const auto& o : owned) {
    const auto r = ask(h, "akd", true, o.index, o.sub, o.size, 0x80000201 & ((1LL << (8 * o.size)) - 1));
    EXPECT_FALSE(r.ok) << std::hex << o.index;
    EXPECT_NE(std::string(r.error.view()).find(o.owner), std::string::npos) << r.error.view();
    EXPECT_NE(std::string(r.error.view()).find("out of the gateway's control"), std::string::npos) << r.error.view();
  }
  // Nothing reached the drive: its RPDO 1 is still valid, and reading it is allowed.
  const auto r = ask(h, "akd", false, 0x1400, 1, 4);
  ASSERT_TRUE(r.ok) << r.error.view();
  EXPECT_EQ(drivegate::test::reply_integer(r) & 0x80000000, 0);
  // Other objects stay writable.
  EXPECT_TRUE(ask(h, "akd", true, 0x6081, 0, 4, 1000).ok);
}

// Whatever the cause (here a service tool switched the RPDO off on the drive's own interface), a
// drive that keeps running while the gateway sends quick stop is found out: a control_lost event,
// the link degraded, the drive stopped over SDO, then reconfigured and back disabled.
TEST(CanopenControl, ADriveThatStopsFollowingIsStoppedOverSdoAndReconfigured) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  ASSERT_EQ(h.wait_final(h.push("akd", CommandKind::Enable), 3s), ReplyStatus::Completed) << h.events_text();
  h.push("akd", CommandKind::Move, 300.0);  // 50 mm/s: a long way
  ASSERT_TRUE(h.run_until([&] { return std::fabs(h.snap("akd").velocity) > 20; }, 3s)) << h.events_text();

  ASSERT_EQ(h.drive("akd").service_write({0x1400, 1}, 0x80000201, 4), 0u);
  const auto boots_before = h.bus->boots(h.axis("akd"));
  const auto stop = h.push("akd", CommandKind::QuickStop);
  ASSERT_TRUE(h.run_until([&] { return h.bus->link_state(h.axis("akd")) == LinkState::Degraded; }, 3s))
      << h.events_text();
  EXPECT_TRUE(has_event(h, core::EventKind::ControlLost, "does not follow its controlword")) << h.events_text();
  // The quick stop that could not be carried out got its final reply, with the reason.
  EXPECT_EQ(h.wait_final(stop, 1s), ReplyStatus::Failed);
  EXPECT_NE(h.reason(stop).find("stopped following"), std::string::npos) << h.reason(stop);
  // Commands are refused while the gateway has no control.
  const auto refused = h.push("akd", CommandKind::Move, 10.0);
  EXPECT_EQ(h.wait_final(refused, 100ms), ReplyStatus::Rejected);
  EXPECT_NE(h.reason(refused).find("link is degraded"), std::string::npos) << h.reason(refused);

  // The drive itself comes to rest and its power stage goes off.
  ASSERT_TRUE(h.run_until([&] { return h.drive("akd").drive().state() == AxisState::SwitchOnDisabled; }, 5s))
      << static_cast<int>(h.drive("akd").drive().state()) << h.events_text();
  // At rest: below 0.1 mm/s (12000 drive units per mm/s), braked on the ramp, not coasting.
  EXPECT_LT(std::fabs(h.drive("akd").drive().read_object({0x606C, 0}).value), 1200);

  // Then it is configured from scratch (its RPDO valid again) and comes back disabled.
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 10s)) << h.events_text();
  EXPECT_GT(h.bus->boots(h.axis("akd")), boots_before);
  EXPECT_EQ(h.drive("akd").pdos().read({0x1400, 1}).value & 0x80000000, 0u);
  EXPECT_EQ(h.snap("akd").state, AxisState::SwitchOnDisabled);
  // And it follows again.
  ASSERT_EQ(h.wait_final(h.push("akd", CommandKind::Enable), 3s), ReplyStatus::Completed) << h.events_text();
  ASSERT_EQ(h.wait_final(h.push("akd", CommandKind::Disable), 3s), ReplyStatus::Completed) << h.events_text();
  EXPECT_EQ(h.drive("akd").drive().state(), AxisState::SwitchOnDisabled);
}

// Another master on the wire (its SYNC and NMT frames, which this gateway did not send) is a bus
// warning, not silence; the gateway's own traffic never counts as such.
TEST(CanopenControl, AnotherMasterOnTheBusIsReported) {
  BusHarness h;
  ASSERT_TRUE(h.run_until([&] { return h.all_up(); }, 5s)) << h.events_text();
  h.run_until([] { return false; }, 500ms);
  EXPECT_EQ(h.bus->foreign_master_frames(), 0u);
  EXPECT_FALSE(has_event(h, core::EventKind::Warning, "another CANopen master"));

  auto rogue = h.peer->bus().connect();
  rogue->open();
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(rogue->send(make_frame(cob::kSync, {}), h.now), SendResult::Sent);
    ASSERT_EQ(rogue->send(make_frame(cob::kNmt, {0x01, 0x00}), h.now), SendResult::Sent);
    h.cycle();
  }
  EXPECT_EQ(h.bus->foreign_master_frames(), 10u);
  std::size_t warnings = 0;
  for (const auto& e : h.events)
    if (e.kind == core::EventKind::Warning && e.axis == core::kNoAxis &&
        std::string(e.text.view()).find("another CANopen master is on bus can0") != std::string::npos)
      ++warnings;
  EXPECT_EQ(warnings, 1u) << h.events_text();  // once, not per frame
}

}  // namespace
}  // namespace drivegate::canopen::test
