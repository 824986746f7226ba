// DdsBridge + Client in one process over real Fast DDS, against FakeRuntime. Each test process uses
// its own domain id and namespace so parallel ctest runs do not see each other.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <gtest/gtest.h>

#include "client/client.hpp"
#include "daemon/dds_bridge.hpp"
#include "drivegate.h"
#include "fake_runtime.hpp"
#include "idl/dds_node.hpp"

namespace drivegate::dds_test {
namespace {

namespace dds = eprosima::fastdds::dds;
using client::Client;
using client::CommandRequest;
using client::Millis;
using client::Outcome;
using SteadyClock = std::chrono::steady_clock;

// DDS discovery takes up to about a second; these bounds are generous so a loaded machine passes.
constexpr Millis kTimeout{10000};

// Domains 20..99: their RTPS ports (7400 + 250 * domain + ...) stay below Linux' ephemeral port
// range (32768+), where another process' outgoing socket can steal a discovery port and make
// discovery fail at random.
std::uint32_t test_domain() { return 20U + static_cast<std::uint32_t>(::getpid() % 80); }

std::string test_namespace() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return "dgtest_" + std::to_string(::getpid()) + "_" + info->name();
}

daemon::DdsBridgeOptions bridge_options(double rate = 20) {
  daemon::DdsBridgeOptions o;
  o.domain = test_domain();
  o.ns = test_namespace();
  o.status_rate_hz = rate;
  return o;
}

client::ClientOptions client_options() {
  client::ClientOptions o;
  o.domain = test_domain();
  o.ns = test_namespace();
  return o;
}

msg::DdsOptions raw_options() {
  msg::DdsOptions o;
  o.domain = test_domain();
  o.ns = test_namespace();
  o.participant_name = "raw-peer";
  return o;
}

// Talks to the bridge on the raw topics, so tests can send what the Client library would refuse.
class RawPeer {
 public:
  RawPeer()
      : node_(raw_options()),
        cmd_w_(node_.writer(msg::TopicId::AxisCommand)),
        reply_r_(node_.reader(msg::TopicId::CommandReply)) {}

  bool wait_matched() {
    return poll([&] {
      dds::PublicationMatchedStatus w{};
      dds::SubscriptionMatchedStatus r{};
      cmd_w_.get_publication_matched_status(w);
      reply_r_.get_subscription_matched_status(r);
      return w.current_count > 0 && r.current_count > 0;
    });
  }

  void send(const std::string& gateway, const std::string& axis, std::uint64_t id, const std::string& kind,
            const std::string& mode = {}) {
    msg::AxisCommand c;
    c.gateway(gateway);
    c.axis(axis);
    c.client("raw");
    c.id(id);
    c.kind(kind);
    c.mode(mode);
    cmd_w_.write(&c);
  }

  // The first reply with this id, if one arrives in time.
  std::optional<msg::CommandReply> reply(std::uint64_t id) {
    std::optional<msg::CommandReply> found;
    poll([&] {
      for (const auto& r : replies_)
        if (r.id() == id) {
          found = r;
          return true;
        }
      return false;
    });
    return found;
  }
  [[nodiscard]] bool has_reply(std::uint64_t id) const {
    return std::any_of(replies_.begin(), replies_.end(), [&](const msg::CommandReply& r) { return r.id() == id; });
  }

 private:
  template <typename F>
  bool poll(F&& done) {
    const auto deadline = SteadyClock::now() + kTimeout;
    for (;;) {
      take();
      if (done()) return true;
      if (SteadyClock::now() >= deadline) return false;
      reply_r_.wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 50'000'000));  // wakes on data
    }
  }
  void take() {
    msg::CommandReply r;
    dds::SampleInfo info;
    while (reply_r_.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) replies_.push_back(r);
  }

  msg::DdsNode node_;
  dds::DataWriter& cmd_w_;
  dds::DataReader& reply_r_;
  std::vector<msg::CommandReply> replies_;
};

// What the client discovered, for failure messages.
std::string seen(const Client& c) {
  return " [client saw " + std::to_string(c.gateways().size()) + " gateways, " + std::to_string(c.states().size()) +
         " axis states]";
}

bool has_axes(const Client& c, std::size_t n) {
  std::size_t total = 0;
  for (const auto& g : c.gateways()) total += g.axes.size();
  return total >= n;
}

TEST(DdsBridge, CommandAcceptedThenCompleted) {
  FakeRuntime rt("gw1", {"x", "y"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());

  CommandRequest req;
  req.axis = "y";
  req.kind = "move";
  req.position = 12.5;
  req.velocity = 3;
  req.relative = true;
  const auto r = c.send(req, true, kTimeout);
  EXPECT_EQ(r.outcome, Outcome::Completed) << r.reason << seen(c);
  EXPECT_EQ(r.gateway, "gw1");
  EXPECT_EQ(r.reason, "target reached");

  const auto cmds = rt.commands();
  ASSERT_EQ(cmds.size(), 1U);
  EXPECT_EQ(cmds[0].axis_id, 1U);
  EXPECT_EQ(cmds[0].command.kind, core::CommandKind::Move);
  EXPECT_DOUBLE_EQ(cmds[0].command.position, 12.5);
  EXPECT_DOUBLE_EQ(cmds[0].command.velocity, 3);
  EXPECT_TRUE(cmds[0].command.relative);
  EXPECT_NE(cmds[0].command.id, 0U);

  // Without waiting for the final reply the client returns at Accepted.
  rt.set_complete_commands(false);
  req.kind = "enable";
  const auto a = c.send(req, false, kTimeout);
  EXPECT_EQ(a.outcome, Outcome::Accepted) << a.reason;
  // Internal ids are unique even though the client's ids are its own.
  const auto all = rt.commands();
  ASSERT_EQ(all.size(), 2U);
  EXPECT_NE(all[0].command.id, all[1].command.id);
}

// A client that only commands does not subscribe to axis_state: the gateway's state writer does not
// send it every state at the status rate. The first states() subscribes and returns them at once.
// A probe participant with its own axis_state writer and axis_command reader sees which endpoints
// the client has.
TEST(DdsBridge, CommandOnlyClientSubscribesToStatesOnFirstRead) {
  FakeRuntime rt("gw1", {"x", "y"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  msg::DdsNode probe(raw_options());
  dds::DataWriter& state_w = probe.writer(msg::TopicId::AxisState);
  dds::DataReader& command_r = probe.reader(msg::TopicId::AxisCommand);
  const auto matched_state_readers = [&] {
    dds::PublicationMatchedStatus m{};
    state_w.get_publication_matched_status(m);
    return m.current_count;
  };
  Client c(client_options());

  CommandRequest req;
  req.axis = "x";
  req.kind = "enable";
  ASSERT_EQ(c.send(req, true, kTimeout).outcome, Outcome::Completed);
  EXPECT_EQ(c.stream_setpoint("x", "gw1", 0, 1, 0), "");
  // The probe has discovered the client's endpoints (the command writer, made after the readers the
  // client made at construction) ...
  ASSERT_TRUE(c.wait_until(
      [&] {
        dds::SubscriptionMatchedStatus m{};
        command_r.get_subscription_matched_status(m);
        return m.current_count > 0;
      },
      kTimeout));
  // ... and no axis_state reader among them.
  EXPECT_FALSE(c.wait_until([&] { return matched_state_readers() > 0; }, Millis(500)));

  // The first read subscribes and waits for the present states: not empty right after subscribing.
  const auto states = c.states();
  ASSERT_EQ(states.size(), 2U);
  EXPECT_EQ(states[0].axis, "x");
  EXPECT_EQ(states[1].axis, "y");
  EXPECT_TRUE(c.wait_until([&] { return matched_state_readers() == 1; }, kTimeout));
  // Likewise links and bus statuses (transient local) on their first read.
  EXPECT_EQ(c.links().size(), 2U);
  ASSERT_EQ(c.buses().size(), 1U);
  EXPECT_EQ(c.buses()[0].bus, "can0");
}

// A command is written only once the addressed gateway's own participant matched the client's
// command writer and reply reader. Another participant's axis_command reader and command_reply
// writer (a monitor, a recorder) matched early must not count: a command written then would be
// lost for the gateway, whose reader matches later.
TEST(DdsBridge, CommandWaitsForTheGatewaysOwnEndpointsNotAnotherParticipants) {
  msg::DdsNode probe(raw_options());
  dds::DataReader& probe_commands = probe.reader(msg::TopicId::AxisCommand);
  probe.writer(msg::TopicId::CommandReply);
  // The gateway announces itself, but makes its command endpoints only later.
  msg::DdsNode gateway(raw_options());
  dds::DataWriter& info_w = gateway.writer(msg::TopicId::GatewayInfo);
  msg::GatewayInfo info;
  info.gateway("gw1");
  info.host("test");
  info.pid(1);
  msg::AxisDescription axis;
  axis.name("x");
  axis.bus("can0");
  info.axes().push_back(axis);
  ASSERT_TRUE(info_w.write(&info));

  Client c(client_options());
  std::optional<client::CommandResult> result;
  std::thread sender([&] {
    CommandRequest req;
    req.axis = "x";
    req.kind = "enable";
    result = c.send(req, true, kTimeout);
  });
  const auto probe_got_command = [&] {
    bool got = false;
    msg::take_valid<msg::AxisCommand>(probe_commands, [&](const msg::AxisCommand&) { got = true; });
    return got;
  };
  // The probe matched the client's endpoints, yet the client does not write to it alone.
  EXPECT_FALSE(c.wait_until(probe_got_command, Millis(1500)));

  dds::DataReader& gw_commands = gateway.reader(msg::TopicId::AxisCommand);
  dds::DataWriter& gw_replies = gateway.writer(msg::TopicId::CommandReply);
  std::optional<msg::AxisCommand> received;
  ASSERT_TRUE(c.wait_until(
      [&] {
        msg::take_valid<msg::AxisCommand>(gw_commands, [&](const msg::AxisCommand& in) { received = in; });
        return received.has_value();
      },
      kTimeout));
  msg::CommandReply reply;
  reply.gateway("gw1");
  reply.axis("x");
  reply.client(received->client());
  reply.id(received->id());
  reply.status("completed");
  ASSERT_TRUE(gw_replies.write(&reply));
  sender.join();
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->outcome, Outcome::Completed) << result->reason;
}

// Every axis' state reaches the client, also beyond Fast DDS's default of 10 instances per topic.
TEST(DdsBridge, StatesOfMoreThanTenAxesAllArrive) {
  std::vector<std::string> names;
  for (int i = 0; i < 24; ++i) names.push_back("a" + std::to_string(i));
  FakeRuntime rt("gw1", names);
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());
  EXPECT_TRUE(c.wait_until([&] { return c.states().size() == names.size(); }, kTimeout)) << c.states().size();
  EXPECT_TRUE(c.wait_until([&] { return c.links().size() == names.size(); }, kTimeout)) << c.links().size();
}

// The first read right after construction, before any gateway was discovered, waits for discovery
// and the gateway's data: not an empty answer that later reads would never correct by waiting.
TEST(DdsBridge, FirstReadRightAfterConstructionWaitsForTheGateway) {
  FakeRuntime rt("gw1", {"x", "y"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());
  EXPECT_EQ(c.states().size(), 2U);
  Client other(client_options());
  EXPECT_EQ(other.links().size(), 2U);
}

// The event history (transient local) reaches the reader after it matched the gateway's writer: the
// first events_since() waits for it instead of returning as soon as the reader matched.
TEST(DdsBridge, FirstEventsReadHasTheHistory) {
  FakeRuntime rt("gw1", {"x"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  constexpr int kEvents = 5;
  for (int i = 0; i < kEvents; ++i) rt.push_event(0, core::EventKind::Warning, "history " + std::to_string(i));
  {
    // The events are published (seen by a first client) before the second client exists.
    Client first(client_options());
    std::uint64_t cursor = 0;
    std::size_t seen_events = 0;
    ASSERT_TRUE(first.wait_until(
        [&] {
          seen_events += first.events_since(cursor).size();
          return seen_events >= kEvents;
        },
        kTimeout));
  }
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return has_axes(c, 1); }, kTimeout)) << seen(c);
  std::uint64_t cursor = 0;
  const auto events = c.events_since(cursor);
  ASSERT_GE(events.size(), static_cast<std::size_t>(kEvents));
  EXPECT_EQ(events.back().text, "history " + std::to_string(kEvents - 1));
}

TEST(DdsBridge, UnknownAxisIsRejectedWithTheAxesWeHave) {
  FakeRuntime rt("gw1", {"x", "y"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  RawPeer peer;
  ASSERT_TRUE(peer.wait_matched());
  peer.send("gw1", "zz", 7, "enable");
  const auto r = peer.reply(7);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status(), "rejected");
  EXPECT_EQ(r->gateway(), "gw1");
  EXPECT_NE(r->reason().find("unknown axis 'zz'"), std::string::npos) << r->reason();
  EXPECT_NE(r->reason().find("x, y"), std::string::npos) << r->reason();
  EXPECT_TRUE(rt.commands().empty());
}

TEST(DdsBridge, UnknownKindModeAndBusyAreRejected) {
  FakeRuntime rt("gw1", {"x"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  RawPeer peer;
  ASSERT_TRUE(peer.wait_matched());

  peer.send("gw1", "x", 1, "teleport");
  auto r = peer.reply(1);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status(), "rejected");
  EXPECT_NE(r->reason().find("unknown command kind 'teleport'"), std::string::npos) << r->reason();

  peer.send("gw1", "x", 2, "set_mode", "warp");
  r = peer.reply(2);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status(), "rejected");
  EXPECT_NE(r->reason().find("unknown mode 'warp'"), std::string::npos) << r->reason();

  rt.set_busy(true);
  peer.send("gw1", "x", 3, "enable");
  r = peer.reply(3);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status(), "rejected");
  EXPECT_NE(r->reason().find("busy: the gateway's command queue for axis 'x' stayed full"), std::string::npos) << r->reason();
  EXPECT_TRUE(rt.commands().empty());
}

TEST(DdsBridge, CommandForAnotherGatewayIsIgnored) {
  FakeRuntime rt("gw1", {"x"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  RawPeer peer;
  ASSERT_TRUE(peer.wait_matched());
  peer.send("gw2", "x", 1, "enable");
  peer.send("gw1", "x", 2, "enable");
  // Replies from one writer arrive in order: once #2 is answered, #1 was never going to be.
  const auto r = peer.reply(2);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->status(), "accepted");
  EXPECT_FALSE(peer.has_reply(1));
  EXPECT_EQ(rt.commands().size(), 1U);
  EXPECT_EQ(bridge.stats().commands_ignored, 1U);
}

TEST(DdsBridge, TwoGatewaysAreListedAndCommandsReachOnlyTheOwner) {
  FakeRuntime rt_a("gwA", {"x", "y"});
  FakeRuntime rt_b("gwB", {"z", "w"});
  daemon::DdsBridge a(rt_a, bridge_options());
  daemon::DdsBridge b(rt_b, bridge_options());
  a.start();
  b.start();
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return has_axes(c, 4); }, kTimeout)) << seen(c);
  const auto gws = c.gateways();
  ASSERT_EQ(gws.size(), 2U);
  EXPECT_EQ(gws[0].name, "gwA");
  EXPECT_EQ(gws[1].name, "gwB");
  EXPECT_EQ(gws[1].axes[0].name, "z");
  EXPECT_EQ(gws[1].axes[0].unit, "mm");
  EXPECT_NE(std::find(gws[1].axes[0].modes.begin(), gws[1].axes[0].modes.end(), "homing"),
            gws[1].axes[0].modes.end());

  CommandRequest req;
  req.axis = "z";
  req.kind = "enable";
  const auto r = c.send(req, true, kTimeout);
  EXPECT_EQ(r.outcome, Outcome::Completed) << r.reason;
  EXPECT_EQ(r.gateway, "gwB");
  EXPECT_EQ(rt_b.commands().size(), 1U);
  EXPECT_TRUE(rt_a.commands().empty());

  // No owner: a clear error naming what is known.
  req.axis = "nope";
  const auto none = c.send(req, true, Millis(300));
  EXPECT_EQ(none.outcome, Outcome::NoGateway);
  EXPECT_NE(none.reason.find("gwB/z"), std::string::npos) << none.reason;

  // States of both gateways arrive.
  ASSERT_TRUE(c.wait_until([&] { return c.states().size() >= 4; }, kTimeout));
  const auto w = c.state("w");
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->gateway, "gwB");
  EXPECT_DOUBLE_EQ(w->position, 11.5);
  EXPECT_EQ(w->state, "switch_on_disabled");
}

// The first two warning events the client sees (fewer when they do not come in time).
std::vector<client::AxisEvent> two_warnings(Client& c) {
  std::uint64_t cursor = 0;
  std::vector<client::AxisEvent> warnings;
  c.wait_until(
      [&] {
        for (auto& e : c.events_since(cursor))
          if (e.kind == "warning" && warnings.size() < 2) warnings.push_back(e);
        return warnings.size() >= 2;
      },
      kTimeout);
  return warnings;
}

// The shared axis is neither gateway's first: every axis of the other gateway is looked at.
TEST(DdsBridge, DuplicateAxisWarningWhenTheSharedAxisIsNotFirstInEitherList) {
  FakeRuntime rt_a("gwA", {"y", "x"});
  FakeRuntime rt_b("gwB", {"z", "w", "x"});
  daemon::DdsBridge a(rt_a, bridge_options());
  daemon::DdsBridge b(rt_b, bridge_options());
  a.start();
  b.start();
  Client c(client_options());
  const auto warnings = two_warnings(c);
  ASSERT_EQ(warnings.size(), 2u);
  std::set<std::string> from;
  for (const auto& e : warnings) {
    EXPECT_EQ(e.axis, "x") << e.text;
    from.insert(e.gateway);
  }
  EXPECT_EQ(from, (std::set<std::string>{"gwA", "gwB"}));
}

TEST(DdsBridge, DuplicateAxisNameAcrossGatewaysRaisesAWarningEvent) {
  FakeRuntime rt_a("gwA", {"x", "y"});
  FakeRuntime rt_b("gwB", {"x", "z"});
  daemon::DdsBridge a(rt_a, bridge_options());
  daemon::DdsBridge b(rt_b, bridge_options());
  a.start();
  b.start();
  Client c(client_options());
  const auto warnings = two_warnings(c);  // each gateway reports the clash once
  ASSERT_EQ(warnings.size(), 2u);
  for (const auto& e : warnings) {
    EXPECT_EQ(e.axis, "x");
    EXPECT_NE(e.text.find("gwA"), std::string::npos) << e.text;
    EXPECT_NE(e.text.find("gwB"), std::string::npos) << e.text;
  }
  EXPECT_NE(warnings[0].gateway, warnings[1].gateway);

  // The client refuses to guess the owner, but an explicit gateway works.
  ASSERT_TRUE(c.wait_until([&] { return has_axes(c, 4); }, kTimeout)) << seen(c);
  EXPECT_NE(c.route("x").error.find("several gateways"), std::string::npos);
  CommandRequest req;
  req.axis = "x";
  req.gateway = "gwB";
  req.kind = "enable";
  EXPECT_EQ(c.send(req, true, kTimeout).outcome, Outcome::Completed);
  EXPECT_EQ(rt_b.commands().size(), 1U);
  EXPECT_TRUE(rt_a.commands().empty());
}

TEST(DdsBridge, StatesArriveAtAboutTheConfiguredRate) {
  constexpr double kRate = 20;
  FakeRuntime rt("gw1", {"x"});
  daemon::DdsBridge bridge(rt, bridge_options(kRate));
  bridge.start();
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return c.state("x").has_value(); }, kTimeout));
  const std::uint64_t seq0 = c.state("x")->seq;
  const auto t0 = SteadyClock::now();
  constexpr std::uint64_t kSamples = 20;
  ASSERT_TRUE(c.wait_until([&] { return c.state("x")->seq >= seq0 + kSamples; }, kTimeout));
  const double seconds = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  const double rate = static_cast<double>(c.state("x")->seq - seq0) / seconds;
  // Generous bounds: the point is "configured rate, not cycle rate or 1 Hz".
  EXPECT_GT(rate, kRate * 0.5);
  EXPECT_LT(rate, kRate * 2.0);
  EXPECT_EQ(c.state("x")->link, "operational");
  EXPECT_EQ(c.state("x")->unit, "mm");

  // Bus status arrives too (at 1 Hz, transient-local).
  ASSERT_TRUE(c.wait_until([&] { return !c.buses().empty(); }, kTimeout));
  EXPECT_EQ(c.buses()[0].type, "canopen");
  EXPECT_EQ(c.buses()[0].cycles, 42U);
}

// The distributed clocks' figures of a bus travel on bus_status; a bus without them (can0 here)
// says so rather than reporting 0 ns.
TEST(DdsBridge, BusStatusCarriesTheClockSyncFiguresOnlyWhereABusHasThem) {
  FakeRuntime rt("gw1", {"x"});
  daemon::BusStatus ec;
  ec.name = "ec0";
  ec.type = "ethercat";
  ec.running = true;
  ec.clock_sync = core::ClockSync{true, 37, -1'250};
  rt.add_bus(ec);
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return c.buses().size() == 2; }, kTimeout));
  for (const auto& b : c.buses()) {
    if (b.bus == "ec0") {
      EXPECT_TRUE(b.clock_sync);
      EXPECT_EQ(b.clock_difference_ns, 37);
      EXPECT_EQ(b.clock_master_offset_ns, -1'250);
    } else {
      EXPECT_EQ(b.bus, "can0");
      EXPECT_FALSE(b.clock_sync);
      EXPECT_EQ(b.clock_difference_ns, 0);
    }
  }
}

// status_keepalive: an unchanged state is written again only after the keep-alive (seq counts the
// 50 ms periods), a changed one at the next period.
TEST(DdsBridge, UnchangedStatesWaitForTheKeepAliveChangedOnesGoAtTheNextPeriod) {
  FakeRuntime rt("gw1", {"x"});
  auto options = bridge_options(20);
  options.status_keepalive = std::chrono::seconds(2);
  daemon::DdsBridge bridge(rt, options);
  bridge.start();
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return c.state("x").has_value(); }, kTimeout));
  const std::uint64_t first = c.state("x")->seq;
  ASSERT_TRUE(c.wait_until([&] { return c.state("x")->seq != first; }, kTimeout));
  const auto kept_alive = SteadyClock::now();
  const std::uint64_t second = c.state("x")->seq;
  // 2 s at 20 Hz: 40 periods (the first sample may have been a keep-alive already under way).
  EXPECT_GE(second - first, 30U) << "an unchanged state was published again after " << second - first << " periods";
  EXPECT_DOUBLE_EQ(c.state("x")->position, 1.5);

  rt.set_position(0, 99.0);
  ASSERT_TRUE(c.wait_until([&] { return c.state("x")->position == 99.0; }, kTimeout));
  // The next keep-alive would be 2 s after the last one.
  EXPECT_LT(SteadyClock::now() - kept_alive, std::chrono::milliseconds(1500));
  EXPECT_LT(c.state("x")->seq - second, 30U);
}

// axis_link: written when the link state or its detail changes, with the axis' bus, bus type and
// address; a client that joins later gets the present one (transient-local).
TEST(DdsBridge, LinkDetailIsPublishedWhenItChanges) {
  FakeRuntime rt("gw1", {"x", "y"});
  rt.set_link(0, core::LinkState::Configuring, "node 35 booted: configuring it", 1'000);
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return c.link("x").has_value() && c.link("y").has_value(); }, kTimeout));
  auto x = *c.link("x");
  EXPECT_EQ(x.gateway, "gw1");
  EXPECT_EQ(x.bus, "can0");
  EXPECT_EQ(x.bus_type, "canopen");
  EXPECT_EQ(x.address, 35U);
  EXPECT_EQ(x.link, "configuring");
  EXPECT_EQ(x.detail, "node 35 booted: configuring it");
  EXPECT_EQ(x.since_ns, 1'000);
  EXPECT_EQ(c.link("y")->link, "operational");

  const std::string failed = "node 35: identity: 1018h:01 reads 0x0000006A, expected 0x00000059";
  rt.set_link(0, core::LinkState::Offline, failed, 2'000);
  ASSERT_TRUE(c.wait_until([&] { return c.link("x")->detail == failed; }, kTimeout));
  EXPECT_EQ(c.link("x")->link, "offline");
  EXPECT_EQ(c.link("x")->since_ns, 2'000);
  // The detail alone changes: published too.
  rt.set_link(0, core::LinkState::Offline, "node 35: asking it again after 1000 ms (SDO read of 1000h)", 2'000);
  ASSERT_TRUE(c.wait_until([&] { return c.link("x")->detail.find("asking it again") != std::string::npos; }, kTimeout));

  Client late(client_options());
  ASSERT_TRUE(late.wait_until([&] { return late.link("x").has_value(); }, kTimeout));
  EXPECT_NE(late.link("x")->detail.find("asking it again"), std::string::npos);
}

TEST(DdsBridge, ParameterGetAndSetRoundTrip) {
  FakeRuntime rt("gw1", {"x", "y"});
  rt.set_object(1, 0x6060, 0, core::ParamType::I8, "1");
  rt.set_object(1, 0x6081, 0, core::ParamType::I32, "0");
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());

  client::ParamRequest get;
  get.axis = "y";
  get.index = 0x6060;
  auto r = c.param(get, kTimeout);
  ASSERT_TRUE(r.ok) << r.error << seen(c);
  EXPECT_EQ(r.type, core::ParamType::I8);
  EXPECT_EQ(r.integer(), 1);
  EXPECT_EQ(r.gateway, "gw1");

  client::ParamRequest set = get;
  set.write = true;
  set.index = 0x6081;
  set.value = "-1234";
  r = c.param(set, kTimeout);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(rt.object(1, 0x6081, 0), (std::vector<std::uint8_t>{0x2E, 0xFB, 0xFF, 0xFF}));

  get.index = 0x6081;
  r = c.param(get, kTimeout);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.integer(), -1234);

  get.index = 0x1234;
  r = c.param(get, kTimeout);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error_code, 0x06020000U);
  EXPECT_NE(r.error.find("does not exist"), std::string::npos);
}

// Every basic type end to end: strings, 64-bit integers, reals and byte strings of up to 4 KiB
// come back byte for byte; a value or type that does not fit is an error naming both, never a
// value cut short.
TEST(DdsBridge, ParametersOfEveryType) {
  FakeRuntime rt("gw1", {"x"});
  rt.set_object(0, 0x1008, 0, core::ParamType::VisibleString, "drivegate simulated servo drive");
  rt.set_object(0, 0x2001, 0, core::ParamType::U64, "0xFFFFFFFFFFFFFFF6");
  rt.set_object(0, 0x2002, 0, core::ParamType::R32, "4.5");
  rt.set_object(0, 0x2004, 0, core::ParamType::Unknown, "01 02 03");
  std::string blob;
  for (int i = 0; i < 4096; ++i) blob += (i % 16 == 0 ? "" : " ") + std::string(1, "0123456789ABCDEF"[i % 16]) + "A";
  rt.set_object(0, 0x2003, 0, core::ParamType::Domain, blob);
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());
  const auto get = [&](std::uint16_t index, std::string type = {}) {
    client::ParamRequest q;
    q.axis = "x";
    q.index = index;
    q.type = std::move(type);
    return c.param(q, kTimeout);
  };
  const auto set = [&](std::uint16_t index, std::string value, std::string type = {}) {
    client::ParamRequest q;
    q.axis = "x";
    q.index = index;
    q.write = true;
    q.value = std::move(value);
    q.type = std::move(type);
    return c.param(q, kTimeout);
  };

  auto r = get(0x1008);
  ASSERT_TRUE(r.ok) << r.error << seen(c);
  EXPECT_EQ(r.type, core::ParamType::VisibleString);
  EXPECT_EQ(r.text(), "drivegate simulated servo drive");
  EXPECT_EQ(r.data.size(), 31U);
  r = get(0x2001);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(core::param_as_unsigned(r.type, r.data), 0xFFFFFFFFFFFFFFF6ULL);
  EXPECT_EQ(r.text(), "18446744073709551606");
  r = get(0x2002);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.text(), "4.5");
  r = get(0x2003);
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_EQ(r.data.size(), 4096U);
  EXPECT_EQ(r.data[4095], 0xFA);
  r = get(0x2004);  // type not known: the bytes as they are
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.type, core::ParamType::Unknown);
  EXPECT_EQ(r.text(), "01 02 03");

  ASSERT_TRUE(set(0x1008, "new name").ok);
  EXPECT_EQ(rt.object(0, 0x1008, 0).size(), 8U);
  ASSERT_TRUE(set(0x2002, "-1e3").ok);
  EXPECT_EQ(get(0x2002).text(), "-1000");
  ASSERT_TRUE(set(0x2004, "0a0b", "octets").ok);  // unknown to the gateway: the request names it

  // Errors name the sizes and types; nothing reaches the object.
  r = get(0x1008, "u32");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "1008h:00 is a VISIBLE_STRING (any length, per the test's dictionary), not a UNSIGNED32 (4 bytes)");
  r = set(0x2001, "-1");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("outside the range of UNSIGNED64 (0 to 18446744073709551615)"), std::string::npos) << r.error;
  r = set(0x2002, "nan");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("not a finite number"), std::string::npos) << r.error;
  r = set(0x2005, "12");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("is not known"), std::string::npos) << r.error;
  r = get(0x2001, "float128");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("unknown type 'float128'"), std::string::npos) << r.error;
  EXPECT_EQ(core::param_as_unsigned(core::ParamType::U64, rt.object(0, 0x2001, 0)), 0xFFFFFFFFFFFFFFF6ULL);
}

// Objects by name (EDS ParameterName or a vendor name): the gateway resolves index, sub-index
// and type; the reply names the object accessed.
TEST(DdsBridge, ParametersByName) {
  FakeRuntime rt("gw1", {"x"});
  daemon::ParameterLookup a83;
  a83.index = 0x2053;
  rt.add_name("A83", a83);
  rt.set_object(0, 0x2053, 0, core::ParamType::U8, "7");
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());

  client::ParamRequest get;
  get.axis = "x";
  get.name = "A83";
  auto r = c.param(get, kTimeout);
  ASSERT_TRUE(r.ok) << r.error << seen(c);
  EXPECT_EQ(r.integer(), 7);
  EXPECT_EQ(r.index, 0x2053);
  EXPECT_EQ(r.subindex, 0);

  get.name = "A840";
  r = c.param(get, kTimeout);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "no object named 'A840'");
}

TEST(DdsBridge, SetpointsAndEventsFlow) {
  FakeRuntime rt("gw1", {"x", "spindle"});
  daemon::DdsBridge bridge(rt, bridge_options());
  bridge.start();
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return has_axes(c, 2); }, kTimeout)) << seen(c);
  // Best effort: stream until one arrives.
  ASSERT_TRUE(c.wait_until(
      [&] {
        EXPECT_EQ(c.stream_setpoint("spindle", "", 0, 250.0, 0), "");
        return !rt.setpoints().empty();
      },
      kTimeout));
  const auto sp = rt.setpoints().back();
  EXPECT_EQ(sp.first, 1U);
  EXPECT_DOUBLE_EQ(sp.second.velocity, 250.0);

  rt.push_event(0, core::EventKind::Fault, "overcurrent \"phase U\"");
  std::uint64_t cursor = 0;
  std::optional<client::AxisEvent> fault;
  ASSERT_TRUE(c.wait_until(
      [&] {
        for (auto& e : c.events_since(cursor))
          if (e.kind == "fault") fault = e;
        return fault.has_value();
      },
      kTimeout));
  EXPECT_EQ(fault->axis, "x");
  EXPECT_EQ(fault->gateway, "gw1");
  EXPECT_EQ(fault->text, "overcurrent \"phase U\"");
}

// The bridge does not poll: idle, it wakes for its publications (here 2 states and 1 bus status a
// second) and nothing else; the old loop came back every 5 ms, 200 times a second. An event the
// Runtime queues wakes it at once, long before its next publication is due.
TEST(DdsBridge, IdleBridgeSleepsUntilWorkOrAPublicationIsDue) {
  FakeRuntime rt("gw1", {"x"});
  daemon::DdsBridge bridge(rt, bridge_options(2));
  bridge.start();
  Client c(client_options());
  ASSERT_TRUE(c.wait_until([&] { return has_axes(c, 1) && c.state("x").has_value(); }, kTimeout)) << seen(c);

  const auto w0 = bridge.stats().wakeups;
  const auto t0 = SteadyClock::now();
  std::this_thread::sleep_for(std::chrono::seconds(2));  // the window observed, not a synchronisation
  const double seconds = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  const auto wakeups = bridge.stats().wakeups - w0;
  EXPECT_LE(static_cast<double>(wakeups), 10 * seconds) << wakeups << " wake-ups in " << seconds << " s";

  // With a 5 s publication period only the Runtime's signal can bring the event out within 2.5 s.
  FakeRuntime slow_rt("gw2", {"y"});
  daemon::DdsBridge slow(slow_rt, bridge_options(0.2));
  slow.start();
  ASSERT_TRUE(c.wait_until([&] { return has_axes(c, 2); }, kTimeout)) << seen(c);
  std::uint64_t cursor = 0;
  (void)c.events_since(cursor);
  slow_rt.push_event(0, core::EventKind::Warning, "woken");
  const auto pushed = SteadyClock::now();
  bool arrived = false;
  ASSERT_TRUE(c.wait_until(
      [&] {
        for (auto& e : c.events_since(cursor)) arrived = arrived || e.text == "woken";
        return arrived;
      },
      kTimeout));
  EXPECT_LT(SteadyClock::now() - pushed, std::chrono::milliseconds(2500));
}

}  // namespace
}  // namespace drivegate::dds_test
