// NmtMaster: NMT command frames, node states from boot-up / heartbeat / guard replies, heartbeat
// timeouts, guarding misses and toggle errors, the master's own heartbeat, and bad input.
#include "adapters/canopen/master/nmt_master.hpp"

#include <gtest/gtest.h>

#include <array>
#include <stdexcept>
#include <vector>

#include "tests/canopen_nmt/nmt_test_support.hpp"

namespace drivegate::canopen::test {
namespace {

std::vector<NmtEvent> events(NmtMaster& m) {
  std::vector<NmtEvent> out;
  NmtEvent e;
  while (m.next_event(e)) out.push_back(e);
  return out;
}

CanFrame ec(NodeId node, std::uint8_t byte) { return make_frame(cob::error_control(node), {byte}); }

NmtMasterConfig no_own_heartbeat() {
  NmtMasterConfig c;
  c.heartbeat_period = core::Duration::zero();
  return c;
}

NmtNodeConfig heartbeat_node(NodeId n, core::Duration timeout = milliseconds(300)) {
  NmtNodeConfig c;
  c.node = n;
  c.watch = Watch::Heartbeat;
  c.heartbeat_timeout = timeout;
  return c;
}

NmtNodeConfig guarded_node(NodeId n, core::Duration guard = milliseconds(100), int factor = 3) {
  NmtNodeConfig c;
  c.node = n;
  c.watch = Watch::Guarding;
  c.guard_time = guard;
  c.life_time_factor = factor;
  return c;
}

TEST(NmtMasterCommand, FramesAreByteExact) {
  const std::array nodes{heartbeat_node(1), heartbeat_node(5)};
  NmtMaster m(no_own_heartbeat(), nodes);
  TxQueue tx;
  // AKD part 1 §14 vectors 18, 19 (node 1); SD6 TV-3 (start all) and D-6 (node 5).
  ASSERT_TRUE(m.command(NmtCommand::Start, 1, tx));
  ASSERT_TRUE(m.command(NmtCommand::Start, 0, tx));
  ASSERT_TRUE(m.command(NmtCommand::Stop, 1, tx));
  ASSERT_TRUE(m.command(NmtCommand::EnterPreOperational, 1, tx));
  ASSERT_TRUE(m.command(NmtCommand::ResetNode, 1, tx));
  ASSERT_TRUE(m.command(NmtCommand::ResetCommunication, 1, tx));
  ASSERT_TRUE(m.command(NmtCommand::Start, 5, tx));
  ASSERT_TRUE(m.command(NmtCommand::Stop, 5, tx));
  ASSERT_TRUE(m.command(NmtCommand::EnterPreOperational, 5, tx));
  ASSERT_TRUE(m.command(NmtCommand::ResetNode, 5, tx));
  ASSERT_TRUE(m.command(NmtCommand::ResetCommunication, 5, tx));
  const auto f = drain(tx);
  ASSERT_EQ(f.size(), 11U);
  EXPECT_TRUE(is_frame(f[0], 0x000, {0x01, 0x01}));
  EXPECT_TRUE(is_frame(f[1], 0x000, {0x01, 0x00}));
  EXPECT_TRUE(is_frame(f[2], 0x000, {0x02, 0x01}));
  EXPECT_TRUE(is_frame(f[3], 0x000, {0x80, 0x01}));
  EXPECT_TRUE(is_frame(f[4], 0x000, {0x81, 0x01}));
  EXPECT_TRUE(is_frame(f[5], 0x000, {0x82, 0x01}));
  EXPECT_TRUE(is_frame(f[6], 0x000, {0x01, 0x05}));
  EXPECT_TRUE(is_frame(f[7], 0x000, {0x02, 0x05}));
  EXPECT_TRUE(is_frame(f[8], 0x000, {0x80, 0x05}));
  EXPECT_TRUE(is_frame(f[9], 0x000, {0x81, 0x05}));
  EXPECT_TRUE(is_frame(f[10], 0x000, {0x82, 0x05}));
}

TEST(NmtMasterCommand, RefusesBadNodeAndFullQueue) {
  NmtMaster m(no_own_heartbeat(), {});
  TxQueue tx;
  EXPECT_FALSE(m.command(NmtCommand::Start, 128, tx));
  EXPECT_TRUE(tx.empty());
  while (tx.size() < 1024) tx.push(CanFrame{});
  EXPECT_FALSE(m.command(NmtCommand::Start, 1, tx));
  EXPECT_EQ(m.counters().tx_full, 1U);
}

TEST(NmtMasterConstruction, RejectsBadNodeTables) {
  const std::array zero{heartbeat_node(0)};
  EXPECT_THROW(NmtMaster(no_own_heartbeat(), zero), std::invalid_argument);
  const std::array high{heartbeat_node(128)};
  EXPECT_THROW(NmtMaster(no_own_heartbeat(), high), std::invalid_argument);
  const std::array twice{heartbeat_node(3), guarded_node(3)};
  EXPECT_THROW(NmtMaster(no_own_heartbeat(), twice), std::invalid_argument);
  NmtMasterConfig bad_own;
  bad_own.own_node = 0;
  EXPECT_THROW(NmtMaster(bad_own, {}), std::invalid_argument);
}

TEST(NmtMasterStates, BootUpAndHeartbeatStates) {
  const std::array nodes{heartbeat_node(1)};
  NmtMaster m(no_own_heartbeat(), nodes);
  EXPECT_EQ(m.state(1), NmtState::Unknown);

  // AKD vector 20: boot-up.
  EXPECT_TRUE(m.on_frame(ec(1, 0x00), at_ms(10)));
  EXPECT_EQ(m.state(1), NmtState::PreOperational);
  EXPECT_EQ(m.last_heard(1), at_ms(10));
  // AKD vector 23: heartbeat operational, pre-operational, stopped.
  EXPECT_TRUE(m.on_frame(ec(1, 0x05), at_ms(20)));
  EXPECT_EQ(m.state(1), NmtState::Operational);
  EXPECT_TRUE(m.on_frame(ec(1, 0x05), at_ms(30)));  // same state: no event
  EXPECT_TRUE(m.on_frame(ec(1, 0x7F), at_ms(40)));
  EXPECT_TRUE(m.on_frame(ec(1, 0x04), at_ms(50)));
  EXPECT_EQ(m.state(1), NmtState::Stopped);
  // SD6 §6.8: bit 7 of a heartbeat is masked (the manual's figure shows a toggle there).
  EXPECT_TRUE(m.on_frame(ec(1, 0x85), at_ms(60)));
  EXPECT_EQ(m.state(1), NmtState::Operational);
  EXPECT_EQ(m.last_heard(1), at_ms(60));

  const auto ev = events(m);
  ASSERT_EQ(ev.size(), 5U);
  EXPECT_EQ(ev[0].kind, NmtEventKind::BootUp);
  EXPECT_EQ(ev[0].node, 1);
  EXPECT_EQ(ev[0].state, NmtState::PreOperational);
  EXPECT_EQ(ev[1].kind, NmtEventKind::StateChanged);
  EXPECT_EQ(ev[1].state, NmtState::Operational);
  EXPECT_EQ(ev[2].state, NmtState::PreOperational);
  EXPECT_EQ(ev[3].state, NmtState::Stopped);
  EXPECT_EQ(ev[4].state, NmtState::Operational);
  EXPECT_EQ(m.counters().boot_ups, 1U);
  EXPECT_EQ(m.counters().heartbeats, 5U);
}

TEST(NmtMasterHeartbeat, LostAtTheExactTimeoutOnceThenRecovered) {
  const std::array nodes{heartbeat_node(1, milliseconds(300))};
  NmtMaster m(no_own_heartbeat(), nodes);
  TxQueue tx;
  EXPECT_EQ(m.next_deadline(), core::TimePoint::max());  // nothing watched, no own heartbeat
  m.watch(1, at_ms(0));
  EXPECT_EQ(m.next_deadline(), at_ms(300));  // silence counts from watch()
  m.on_frame(ec(1, 0x05), at_ms(50));
  EXPECT_EQ(m.next_deadline(), at_ms(350));
  events(m);

  m.poll(at_ms(350) - nanoseconds(1), tx);
  EXPECT_FALSE(m.lost(1));
  EXPECT_TRUE(events(m).empty());
  m.poll(at_ms(350), tx);
  EXPECT_TRUE(m.lost(1));
  auto ev = events(m);
  ASSERT_EQ(ev.size(), 1U);
  EXPECT_EQ(ev[0].kind, NmtEventKind::Lost);
  EXPECT_EQ(ev[0].node, 1);
  EXPECT_EQ(m.next_deadline(), core::TimePoint::max());  // lost: nothing to time any more

  m.poll(at_ms(2000), tx);  // Lost is reported once
  EXPECT_TRUE(events(m).empty());
  EXPECT_EQ(m.counters().losses, 1U);
  EXPECT_TRUE(tx.empty());  // heartbeat consumption sends nothing

  m.on_frame(ec(1, 0x05), at_ms(2100));
  EXPECT_FALSE(m.lost(1));
  ev = events(m);
  ASSERT_EQ(ev.size(), 1U);  // same state as before: Recovered only
  EXPECT_EQ(ev[0].kind, NmtEventKind::Recovered);
  EXPECT_EQ(ev[0].state, NmtState::Operational);
  EXPECT_EQ(m.next_deadline(), at_ms(2400));
}

TEST(NmtMasterHeartbeat, BootUpAfterLossIsABootUpAndEndsTheWatch) {
  const std::array nodes{heartbeat_node(1)};
  NmtMaster m(no_own_heartbeat(), nodes);
  TxQueue tx;
  m.watch(1, at_ms(0));
  m.poll(at_ms(300), tx);
  ASSERT_TRUE(m.lost(1));
  events(m);

  m.on_frame(ec(1, 0x00), at_ms(500));
  EXPECT_FALSE(m.lost(1));
  const auto ev = events(m);
  ASSERT_EQ(ev.size(), 1U);
  EXPECT_EQ(ev[0].kind, NmtEventKind::BootUp);
  // The node's heartbeat producer is back at its default: no timeout until it is configured.
  EXPECT_EQ(m.next_deadline(), core::TimePoint::max());
  m.poll(at_ms(5000), tx);
  EXPECT_FALSE(m.lost(1));
  m.watch(1, at_ms(5000));
  EXPECT_EQ(m.next_deadline(), at_ms(5300));
}

TEST(NmtMasterHeartbeat, UnwatchStopsTheTimeout) {
  const std::array nodes{heartbeat_node(1)};
  NmtMaster m(no_own_heartbeat(), nodes);
  TxQueue tx;
  m.watch(1, at_ms(0));
  m.unwatch(1);
  EXPECT_EQ(m.next_deadline(), core::TimePoint::max());
  m.poll(at_ms(1000), tx);
  EXPECT_FALSE(m.lost(1));
}

TEST(NmtMasterOwnHeartbeat, SentEveryPeriodOnItsGrid) {
  NmtMasterConfig cfg;
  cfg.own_node = 127;
  cfg.heartbeat_period = milliseconds(100);
  NmtMaster m(cfg, {});
  TxQueue tx;
  EXPECT_EQ(m.next_deadline(), core::TimePoint::min());  // due at the first poll
  m.poll(at_ms(0), tx);
  auto f = drain(tx);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x77F, {0x05}));
  for (int k = 1; k <= 10; ++k) {
    EXPECT_EQ(m.next_deadline(), at_ms(100 * k));
    m.poll(at_ms(100 * k) - nanoseconds(1), tx);
    EXPECT_TRUE(tx.empty()) << "early at period " << k;
    m.poll(at_ms(100 * k) + milliseconds(7), tx);  // jitter does not move the grid
    f = drain(tx);
    ASSERT_EQ(f.size(), 1U);
    EXPECT_TRUE(is_frame(f[0], 0x77F, {0x05}));
  }
  // A poll 3.5 periods late sends one heartbeat, not a burst, and the next is a period away.
  m.poll(at_ms(1450), tx);
  EXPECT_EQ(drain(tx).size(), 1U);
  EXPECT_EQ(m.next_deadline(), at_ms(1550));
}

class Guarding : public ::testing::Test {
 protected:
  static constexpr NodeId kNode = 5;
  std::array<NmtNodeConfig, 1> nodes_{guarded_node(kNode, milliseconds(100), 3)};
  NmtMaster m_{no_own_heartbeat(), nodes_};
  TxQueue tx_;

  // Poll at t and expect exactly one RTR on 705h (SD6 D-5: RTR DLC 1 every guard time).
  void expect_rtr(std::int64_t t_ms) {
    m_.poll(at_ms(t_ms), tx_);
    const auto f = drain(tx_);
    ASSERT_EQ(f.size(), 1U) << "at " << t_ms << " ms";
    EXPECT_TRUE(is_rtr(f[0], 0x705));
  }
  void reply(std::uint8_t byte, std::int64_t t_ms) { EXPECT_TRUE(m_.on_frame(ec(kNode, byte), at_ms(t_ms))); }
};

TEST_F(Guarding, RtrEveryGuardTimeAndAlternatingReplies) {
  m_.on_frame(ec(kNode, 0x00), at_ms(0));  // boot-up
  m_.watch(kNode, at_ms(10));
  EXPECT_EQ(m_.next_deadline(), at_ms(10));
  // AKD vector 26 / SD6 D-5: 05, 85, 05, ... in Operational.
  const std::array<std::uint8_t, 6> replies{0x05, 0x85, 0x05, 0x85, 0x05, 0x85};
  for (std::size_t k = 0; k < replies.size(); ++k) {
    const auto t = 10 + 100 * static_cast<std::int64_t>(k);
    expect_rtr(t);
    EXPECT_EQ(m_.next_deadline(), at_ms(t + 100));
    reply(replies[k], t + 2);
  }
  EXPECT_EQ(m_.state(kNode), NmtState::Operational);
  EXPECT_EQ(m_.counters().guard_replies, 6U);
  EXPECT_EQ(m_.counters().toggle_errors, 0U);
  EXPECT_FALSE(m_.lost(kNode));
  const auto ev = events(m_);
  ASSERT_EQ(ev.size(), 2U);
  EXPECT_EQ(ev[0].kind, NmtEventKind::BootUp);
  EXPECT_EQ(ev[1].kind, NmtEventKind::StateChanged);
  EXPECT_EQ(ev[1].state, NmtState::Operational);
}

TEST_F(Guarding, MissesReachTheLifeTimeFactorThenRecovery) {
  m_.watch(kNode, at_ms(0));
  expect_rtr(0);
  reply(0x05, 1);
  expect_rtr(100);  // unanswered from here on
  expect_rtr(200);  // miss 1
  expect_rtr(300);  // miss 2
  EXPECT_FALSE(m_.lost(kNode));
  events(m_);
  expect_rtr(400);  // miss 3 = life time factor
  EXPECT_TRUE(m_.lost(kNode));
  auto ev = events(m_);
  ASSERT_EQ(ev.size(), 1U);
  EXPECT_EQ(ev[0].kind, NmtEventKind::Lost);
  expect_rtr(500);  // guarding goes on while lost, so recovery is seen
  EXPECT_TRUE(events(m_).empty());
  EXPECT_EQ(m_.counters().losses, 1U);

  reply(0x85, 501);  // the answer to the RTR at 500, second reply of the node: toggle 1
  EXPECT_FALSE(m_.lost(kNode));
  ev = events(m_);
  ASSERT_EQ(ev.size(), 1U);
  EXPECT_EQ(ev[0].kind, NmtEventKind::Recovered);
}

TEST_F(Guarding, RepeatedWrongTogglesAreMissesUpToLost) {
  m_.watch(kNode, at_ms(0));
  // A responder that never toggles after its first reply.
  expect_rtr(0);
  reply(0x05, 1);
  for (int k = 1; k <= 3; ++k) {
    expect_rtr(100 * k);
    reply(0x05, 100 * k + 1);
  }
  EXPECT_EQ(m_.counters().toggle_errors, 3U);
  EXPECT_TRUE(m_.lost(kNode));
  const auto ev = events(m_);
  ASSERT_EQ(ev.size(), 5U);
  EXPECT_EQ(ev[0].kind, NmtEventKind::StateChanged);
  EXPECT_EQ(ev[1].kind, NmtEventKind::ToggleError);
  EXPECT_EQ(ev[1].node, kNode);
  EXPECT_EQ(ev[2].kind, NmtEventKind::ToggleError);
  EXPECT_EQ(ev[3].kind, NmtEventKind::ToggleError);
  EXPECT_EQ(ev[4].kind, NmtEventKind::Lost);
}

TEST_F(Guarding, OneLostReplyCostsMissesButResynchronises) {
  m_.watch(kNode, at_ms(0));
  expect_rtr(0);
  reply(0x05, 1);
  expect_rtr(100);  // the node answers 85, which the bus loses
  expect_rtr(200);  // miss
  reply(0x05, 201);  // toggle 0 where 1 was expected: toggle error, miss, resync
  expect_rtr(300);
  reply(0x85, 301);  // in step again
  expect_rtr(400);
  reply(0x05, 401);
  EXPECT_EQ(m_.counters().toggle_errors, 1U);
  EXPECT_FALSE(m_.lost(kNode));
  // A fresh good reply cleared the count: three more misses are needed for Lost.
  expect_rtr(500);
  expect_rtr(600);
  expect_rtr(700);
  EXPECT_FALSE(m_.lost(kNode));
  expect_rtr(800);
  EXPECT_TRUE(m_.lost(kNode));
}

TEST_F(Guarding, ToggleRestartsAtZeroAfterBootUp) {
  m_.watch(kNode, at_ms(0));
  expect_rtr(0);
  reply(0x05, 1);
  expect_rtr(100);
  reply(0x85, 101);
  expect_rtr(200);
  m_.on_frame(ec(kNode, 0x00), at_ms(250));  // rebooted instead of answering
  EXPECT_EQ(m_.next_deadline(), core::TimePoint::max());  // watch ended
  m_.watch(kNode, at_ms(400));
  expect_rtr(400);
  reply(0x7F, 401);  // pre-operational, toggle 0 again
  EXPECT_EQ(m_.counters().toggle_errors, 0U);
  EXPECT_EQ(m_.state(kNode), NmtState::PreOperational);
}

TEST_F(Guarding, ResetCommandRestartsTheToggleWithoutBootUp) {
  m_.watch(kNode, at_ms(0));
  expect_rtr(0);
  reply(0x05, 1);
  // SD6 quirk 9: after Reset Communication the node may not send a boot-up, but its toggle restarts.
  ASSERT_TRUE(m_.command(NmtCommand::ResetCommunication, kNode, tx_));
  drain(tx_);
  expect_rtr(100);
  reply(0x7F, 101);
  EXPECT_EQ(m_.counters().toggle_errors, 0U);
  EXPECT_EQ(m_.state(kNode), NmtState::PreOperational);
}

TEST_F(Guarding, ReplyWithoutRequestIsUnexpected) {
  m_.watch(kNode, at_ms(0));
  expect_rtr(0);
  reply(0x05, 1);
  reply(0x85, 2);  // a second reply to one RTR
  EXPECT_EQ(m_.counters().unexpected, 1U);
  EXPECT_EQ(m_.counters().guard_replies, 1U);
  expect_rtr(100);
  reply(0x85, 101);  // the expected toggle did not move
  EXPECT_EQ(m_.counters().toggle_errors, 0U);
}

TEST(NmtMasterDeadline, EarliestOfAllTimers) {
  NmtMasterConfig cfg;
  cfg.heartbeat_period = milliseconds(100);
  const std::array nodes{heartbeat_node(1, milliseconds(250)), guarded_node(2, milliseconds(40)),
                         heartbeat_node(3, milliseconds(1000))};
  NmtMaster m(cfg, nodes);
  TxQueue tx;
  m.poll(at_ms(0), tx);  // own heartbeat: next at 100
  EXPECT_EQ(m.next_deadline(), at_ms(100));
  m.watch(3, at_ms(0));
  EXPECT_EQ(m.next_deadline(), at_ms(100));
  m.watch(1, at_ms(-200));  // heartbeat deadline 50
  EXPECT_EQ(m.next_deadline(), at_ms(50));
  m.watch(2, at_ms(30));  // first RTR due at 30
  EXPECT_EQ(m.next_deadline(), at_ms(30));
  m.poll(at_ms(30), tx);
  EXPECT_EQ(m.next_deadline(), at_ms(50));
  m.poll(at_ms(50), tx);  // node 1 lost
  EXPECT_EQ(m.next_deadline(), at_ms(70));  // next RTR
  m.unwatch(2);
  EXPECT_EQ(m.next_deadline(), at_ms(100));
}

TEST(NmtMasterBadInput, CountedAndDroppedWithoutStateChange) {
  const std::array nodes{heartbeat_node(1), guarded_node(2)};
  NmtMaster m(no_own_heartbeat(), nodes);
  m.on_frame(ec(1, 0x05), at_ms(0));
  events(m);

  CanFrame dlc0 = ec(1, 0x7F);
  dlc0.dlc = 0;
  CanFrame dlc2 = make_frame(0x701, {0x7F, 0x00});
  CanFrame dlc9 = ec(1, 0x7F);
  dlc9.dlc = 9;
  EXPECT_TRUE(m.on_frame(dlc0, at_ms(1)));
  EXPECT_TRUE(m.on_frame(dlc2, at_ms(2)));
  EXPECT_TRUE(m.on_frame(dlc9, at_ms(3)));
  EXPECT_TRUE(m.on_frame(ec(1, 0x03), at_ms(4)));  // unknown state byte
  EXPECT_TRUE(m.on_frame(ec(1, 0x80), at_ms(5)));  // boot-up with toggle
  EXPECT_EQ(m.counters().malformed, 5U);

  EXPECT_TRUE(m.on_frame(ec(9, 0x05), at_ms(6)));     // node 9 is not registered
  EXPECT_TRUE(m.on_frame(ec(9, 0x00), at_ms(6)));     // nor is its boot-up
  EXPECT_TRUE(m.on_frame(rtr(0x701), at_ms(7)));      // an RTR: another master?
  EXPECT_TRUE(m.on_frame(make_frame(0x700, {0x05}), at_ms(8)));  // node 0
  EXPECT_EQ(m.counters().unexpected, 4U);

  CanFrame ext = ec(1, 0x7F);
  ext.extended = true;
  EXPECT_FALSE(m.on_frame(ext, at_ms(9)));
  EXPECT_FALSE(m.on_frame(make_frame(0x000, {0x01, 0x01}), at_ms(9)));
  EXPECT_FALSE(m.on_frame(make_frame(0x081, {0x00, 0x00, 0x00}), at_ms(9)));
  EXPECT_FALSE(m.on_frame(make_frame(0x581, {0x60}), at_ms(9)));

  EXPECT_EQ(m.state(1), NmtState::Operational);
  EXPECT_EQ(m.last_heard(1), at_ms(0));
  EXPECT_EQ(m.state(9), NmtState::Unknown);
  EXPECT_TRUE(events(m).empty());
}

TEST(NmtMasterEvents, OverflowIsCounted) {
  const std::array nodes{heartbeat_node(1)};
  NmtMaster m(no_own_heartbeat(), nodes);
  for (std::size_t k = 0; k < NmtMaster::kEventCapacity + 10; ++k) {
    m.on_frame(ec(1, k % 2 == 0 ? 0x05 : 0x7F), at_ms(static_cast<std::int64_t>(k)));
  }
  EXPECT_EQ(m.counters().events_dropped, 10U);
  const auto ev = events(m);
  ASSERT_EQ(ev.size(), NmtMaster::kEventCapacity);
  EXPECT_EQ(ev.front().state, NmtState::Operational);  // the oldest are kept
}

}  // namespace
}  // namespace drivegate::canopen::test
