// NmtSlave: boot-up, the NMT state machine and its service table, heartbeat producer, guard
// responder, life guarding, heartbeat consumer, resets, persona options, silence and bad input.
#include "adapters/canopen/sim/nmt_slave.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "tests/canopen_nmt/nmt_test_support.hpp"

namespace drivegate::canopen::test {
namespace {

using sim::NmtService;
using sim::NmtSlave;
using sim::NmtSlaveConfig;
using sim::NmtSlaveEvent;
using sim::NmtSlaveEventKind;

std::vector<NmtSlaveEvent> events(NmtSlave& s) {
  std::vector<NmtSlaveEvent> out;
  NmtSlaveEvent e;
  while (s.next_event(e)) out.push_back(e);
  return out;
}

std::vector<NmtSlaveEventKind> kinds(NmtSlave& s) {
  std::vector<NmtSlaveEventKind> out;
  for (const auto& e : events(s)) out.push_back(e.kind);
  return out;
}

CanFrame nmt(std::uint8_t cs, std::uint8_t node) { return make_frame(0x000, {cs, node}); }

class Slave : public ::testing::Test {
 protected:
  static constexpr NodeId kNode = 5;

  static NmtSlaveConfig config() {
    NmtSlaveConfig c;
    c.node = kNode;
    return c;
  }

  // Powers on at 0 and polls the boot-up out.
  void boot(NmtSlave& s) {
    s.power_on(at_ms(0));
    s.poll(at_ms(0), tx_);
    const auto f = drain(tx_);
    ASSERT_EQ(f.size(), 1U);
    ASSERT_TRUE(is_frame(f[0], 0x705, {0x00}));
    events(s);
  }
  std::vector<CanFrame> poll(NmtSlave& s, std::int64_t t_ms) {
    s.poll(at_ms(t_ms), tx_);
    return drain(tx_);
  }

  TxQueue tx_;
};

TEST_F(Slave, PowerOnSendsBootUpAndEntersPreOperational) {
  NmtSlave s(config());
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());  // not powered
  s.power_on(at_ms(0));
  EXPECT_EQ(s.state(), NmtState::Initialising);
  EXPECT_EQ(s.next_deadline(), at_ms(0));
  const auto f = poll(s, 0);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x00}));  // SD6 TV-4
  EXPECT_EQ(s.state(), NmtState::PreOperational);
  EXPECT_EQ(s.counters().boot_ups_sent, 1U);
  const auto ev = events(s);
  ASSERT_EQ(ev.size(), 1U);
  EXPECT_EQ(ev[0].kind, NmtSlaveEventKind::StateChanged);
  EXPECT_EQ(ev[0].state, NmtState::PreOperational);
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());  // no heartbeat, no guarding yet
}

TEST_F(Slave, NmtCommandsAndTheServiceTable) {
  NmtSlave s(config());
  boot(s);
  // SD6 §6.7: Pre-operational serves SDO, SYNC and EMCY but no PDO.
  EXPECT_TRUE(s.serves(NmtService::Sdo));
  EXPECT_TRUE(s.serves(NmtService::Sync));
  EXPECT_TRUE(s.serves(NmtService::Emcy));
  EXPECT_FALSE(s.serves(NmtService::Pdo));

  EXPECT_TRUE(s.on_frame(nmt(0x01, 0x00), at_ms(1)));  // TV-3: start all nodes
  EXPECT_EQ(s.state(), NmtState::Operational);
  EXPECT_TRUE(s.serves(NmtService::Pdo));
  EXPECT_TRUE(s.serves(NmtService::Sdo));

  EXPECT_TRUE(s.on_frame(nmt(0x02, 0x05), at_ms(2)));  // D-6 stop
  EXPECT_EQ(s.state(), NmtState::Stopped);
  EXPECT_FALSE(s.serves(NmtService::Sdo));
  EXPECT_FALSE(s.serves(NmtService::Pdo));
  EXPECT_FALSE(s.serves(NmtService::Emcy));
  EXPECT_FALSE(s.serves(NmtService::Sync));

  EXPECT_TRUE(s.on_frame(nmt(0x01, 0x06), at_ms(3)));  // another node
  EXPECT_EQ(s.state(), NmtState::Stopped);
  EXPECT_TRUE(s.on_frame(nmt(0x80, 0x05), at_ms(4)));  // D-6 pre-operational
  EXPECT_EQ(s.state(), NmtState::PreOperational);
  EXPECT_TRUE(s.on_frame(nmt(0x80, 0x05), at_ms(5)));  // again: no change, no event
  EXPECT_EQ(s.counters().nmt_commands, 4U);

  const auto ev = events(s);
  ASSERT_EQ(ev.size(), 3U);
  EXPECT_EQ(ev[0].state, NmtState::Operational);
  EXPECT_EQ(ev[1].state, NmtState::Stopped);
  EXPECT_EQ(ev[2].state, NmtState::PreOperational);
  EXPECT_TRUE(poll(s, 10).empty());  // state changes send nothing by themselves
}

TEST_F(Slave, HeartbeatProducerCarriesTheState) {
  auto cfg = config();
  cfg.heartbeat_period_ms = 100;  // SD6 D-4
  NmtSlave s(cfg);
  boot(s);
  EXPECT_EQ(s.next_deadline(), at_ms(100));
  EXPECT_TRUE(poll(s, 99).empty());
  auto f = poll(s, 100);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x7F}));
  s.on_frame(nmt(0x01, 0x05), at_ms(150));
  f = poll(s, 200);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x05}));
  s.on_frame(nmt(0x02, 0x05), at_ms(250));
  f = poll(s, 300);  // heartbeat runs in Stopped too (SD6 §6.7)
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x04}));
  EXPECT_EQ(s.counters().heartbeats_sent, 3U);

  s.set_heartbeat_period(0, at_ms(310));  // 1017h = 0: off
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());
  EXPECT_TRUE(poll(s, 1000).empty());
  s.set_heartbeat_period(50, at_ms(1000));
  EXPECT_EQ(s.next_deadline(), at_ms(1050));
  EXPECT_EQ(s.heartbeat_period(), 50);
}

TEST_F(Slave, GuardRepliesToggleFromZero) {
  NmtSlave s(config());
  boot(s);
  s.on_frame(rtr(0x705), at_ms(10));
  EXPECT_EQ(s.next_deadline(), at_ms(10));  // the reply is due at once
  auto f = poll(s, 10);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x7F}));  // pre-operational, toggle 0
  s.on_frame(nmt(0x01, 0x05), at_ms(15));
  // AKD vector 26 / SD6 D-5 in Operational: the toggle goes on from where it was.
  std::vector<std::uint8_t> got;
  for (int k = 0; k < 4; ++k) {
    s.on_frame(rtr(0x705), at_ms(20 + k));
    for (const auto& r : poll(s, 20 + k)) got.push_back(r.data[0]);
  }
  EXPECT_EQ(got, (std::vector<std::uint8_t>{0x85, 0x05, 0x85, 0x05}));
  s.on_frame(rtr(0x705, 0), at_ms(30));  // DLC 0 requests are answered too
  f = poll(s, 30);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x85}));
  EXPECT_EQ(s.counters().guard_replies, 6U);
}

TEST_F(Slave, ResetNodeRestoresCommunicationObjectsAndBootsAgain) {
  auto cfg = config();
  cfg.heartbeat_period_ms = 0;
  NmtSlave s(cfg);
  boot(s);
  s.on_frame(nmt(0x01, 0x05), at_ms(1));
  s.on_frame(rtr(0x705), at_ms(2));
  poll(s, 2);  // reply 05, toggle now 1
  s.set_guarding(100, 3, at_ms(3));
  events(s);

  EXPECT_TRUE(s.on_frame(nmt(0x81, 0x00), at_ms(10)));  // reset all nodes
  EXPECT_EQ(s.state(), NmtState::Initialising);
  EXPECT_EQ(s.guard_time(), 0);  // back at the power-on value
  EXPECT_EQ(s.life_time_factor(), 0);
  EXPECT_FALSE(s.serves(NmtService::Sdo));
  auto f = poll(s, 10);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x00}));
  EXPECT_EQ(s.state(), NmtState::PreOperational);
  EXPECT_EQ(kinds(s), (std::vector{NmtSlaveEventKind::ResetNode, NmtSlaveEventKind::StateChanged,
                                   NmtSlaveEventKind::StateChanged}));
  s.on_frame(rtr(0x705), at_ms(20));
  f = poll(s, 20);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x7F}));  // toggle restarted at 0
}

TEST_F(Slave, ResetCommunicationWithoutBootUpPersona) {
  auto cfg = config();
  cfg.heartbeat_period_ms = 100;
  cfg.options.boot_up_after_reset = false;  // SD6 quirk 9
  NmtSlave s(cfg);
  boot(s);  // power-on still announces itself
  s.set_heartbeat_period(20, at_ms(5));
  s.on_frame(nmt(0x01, 0x05), at_ms(6));
  events(s);
  EXPECT_TRUE(s.on_frame(nmt(0x82, 0x05), at_ms(50)));
  EXPECT_EQ(s.heartbeat_period(), 100);  // 1017h back at its power-on value
  EXPECT_TRUE(poll(s, 50).empty());      // no boot-up
  EXPECT_EQ(s.state(), NmtState::PreOperational);
  EXPECT_EQ(kinds(s), (std::vector{NmtSlaveEventKind::ResetCommunication, NmtSlaveEventKind::StateChanged,
                                   NmtSlaveEventKind::StateChanged}));
  EXPECT_EQ(s.next_deadline(), at_ms(150));
  const auto f = poll(s, 150);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x7F}));
}

TEST_F(Slave, LifeGuardingFiresAtGuardTimeTimesFactorOnce) {
  auto cfg = config();
  cfg.guard_time_ms = 100;  // SD6 D-5 / AKD vector 24: 100 ms x 3
  cfg.life_time_factor = 3;
  NmtSlave s(cfg);
  boot(s);
  poll(s, 5000);
  EXPECT_TRUE(events(s).empty());  // guarding starts with the first RTR (AKD part 1 §11.1)
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());

  s.on_frame(rtr(0x705), at_ms(6000));
  poll(s, 6000);
  EXPECT_EQ(s.next_deadline(), at_ms(6300));
  s.on_frame(rtr(0x705), at_ms(6100));
  poll(s, 6100);
  EXPECT_EQ(s.next_deadline(), at_ms(6400));
  s.poll(at_ms(6400) - nanoseconds(1), tx_);
  EXPECT_TRUE(events(s).empty());
  s.poll(at_ms(6400), tx_);
  auto ev = events(s);
  ASSERT_EQ(ev.size(), 1U);
  EXPECT_EQ(ev[0].kind, NmtSlaveEventKind::LifeGuarding);
  EXPECT_EQ(ev[0].state, NmtState::PreOperational);  // in Pre-op too: AKD F129 in any state
  poll(s, 9000);
  EXPECT_TRUE(events(s).empty());  // once per loss
  EXPECT_EQ(s.counters().life_guarding, 1U);

  s.on_frame(rtr(0x705), at_ms(9000));  // guarding resumes: re-armed
  poll(s, 9000);
  poll(s, 9300);
  EXPECT_EQ(kinds(s), std::vector{NmtSlaveEventKind::LifeGuarding});
}

TEST_F(Slave, LifeGuardingOnlyInOperationalPersona) {
  auto cfg = config();
  cfg.guard_time_ms = 100;
  cfg.life_time_factor = 3;
  cfg.options.life_guarding_only_operational = true;  // SD6 quirk 8
  NmtSlave s(cfg);
  boot(s);
  s.on_frame(rtr(0x705), at_ms(10));
  poll(s, 10);
  poll(s, 310);
  EXPECT_TRUE(events(s).empty());
  EXPECT_EQ(s.counters().life_guarding, 1U);  // timed out, but not an event in Pre-op

  s.on_frame(nmt(0x01, 0x05), at_ms(400));
  s.on_frame(rtr(0x705), at_ms(400));
  poll(s, 400);
  events(s);
  poll(s, 700);
  EXPECT_EQ(kinds(s), std::vector{NmtSlaveEventKind::LifeGuarding});
}

TEST_F(Slave, GuardingZeroDisablesLifeGuarding) {
  auto cfg = config();
  cfg.guard_time_ms = 100;
  cfg.life_time_factor = 3;
  NmtSlave s(cfg);
  boot(s);
  s.on_frame(rtr(0x705), at_ms(10));
  poll(s, 10);
  s.set_guarding(100, 0, at_ms(20));  // 100Dh = 0
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());
  poll(s, 5000);
  EXPECT_TRUE(events(s).empty());
  s.set_guarding(50, 2, at_ms(5000));  // a new life time from the write
  EXPECT_EQ(s.next_deadline(), at_ms(5100));
}

TEST_F(Slave, HeartbeatConsumerStartsWithTheFirstHeartbeat) {
  auto cfg = config();
  cfg.heartbeat_consumer = (127U << 16) | 250U;  // AKD vector 22: watch node 127 for 250 ms
  NmtSlave s(cfg);
  boot(s);
  poll(s, 1000);
  EXPECT_TRUE(events(s).empty());  // not armed before the producer was heard
  EXPECT_FALSE(s.on_frame(make_frame(0x77E, {0x05}), at_ms(1000)));  // not the consumed producer
  EXPECT_TRUE(s.on_frame(make_frame(0x77F, {0x05}), at_ms(1000)));
  EXPECT_EQ(s.next_deadline(), at_ms(1250));
  EXPECT_TRUE(s.on_frame(make_frame(0x77F, {0x05}), at_ms(1100)));
  s.poll(at_ms(1350) - nanoseconds(1), tx_);
  EXPECT_TRUE(events(s).empty());
  s.poll(at_ms(1350), tx_);
  const auto ev = events(s);
  ASSERT_EQ(ev.size(), 1U);
  EXPECT_EQ(ev[0].kind, NmtSlaveEventKind::HeartbeatLost);
  poll(s, 5000);
  EXPECT_TRUE(events(s).empty());
  EXPECT_EQ(s.counters().heartbeat_lost, 1U);
  EXPECT_TRUE(tx_.empty());

  s.set_heartbeat_consumer(0);  // off: heartbeats of 127 are no longer taken
  EXPECT_FALSE(s.on_frame(make_frame(0x77F, {0x05}), at_ms(5000)));
  EXPECT_EQ(s.heartbeat_consumer(), 0U);
}

TEST_F(Slave, SilentNodeSendsNothingAndIgnoresEverything) {
  auto cfg = config();
  cfg.heartbeat_period_ms = 100;
  NmtSlave s(cfg);
  s.set_silent(true);
  s.power_on(at_ms(0));
  EXPECT_TRUE(poll(s, 0).empty());  // the boot-up is lost
  EXPECT_EQ(s.state(), NmtState::PreOperational);
  EXPECT_TRUE(s.on_frame(nmt(0x01, 0x05), at_ms(10)));
  EXPECT_TRUE(s.on_frame(rtr(0x705), at_ms(20)));
  EXPECT_EQ(s.state(), NmtState::PreOperational);
  EXPECT_TRUE(poll(s, 100).empty());
  EXPECT_EQ(s.counters().ignored, 2U);
  EXPECT_EQ(s.counters().heartbeats_sent, 0U);

  s.set_silent(false);
  const auto f = poll(s, 200);
  ASSERT_EQ(f.size(), 1U);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x7F}));
}

TEST_F(Slave, BadInputIsCountedAndDropped) {
  auto cfg = config();
  cfg.heartbeat_consumer = (127U << 16) | 250U;
  NmtSlave s(cfg);
  // Before power-on and while initialising, nothing is taken.
  EXPECT_TRUE(s.on_frame(nmt(0x01, 0x05), at_ms(0)));
  EXPECT_EQ(s.counters().ignored, 1U);
  boot(s);

  EXPECT_TRUE(s.on_frame(make_frame(0x000, {0x01}), at_ms(1)));               // DLC 1
  EXPECT_TRUE(s.on_frame(make_frame(0x000, {0x01, 0x05, 0x00}), at_ms(1)));   // DLC 3
  EXPECT_TRUE(s.on_frame(nmt(0x03, 0x05), at_ms(1)));                         // unknown cs
  EXPECT_TRUE(s.on_frame(nmt(0x01, 0x80), at_ms(1)));                         // node 128
  EXPECT_TRUE(s.on_frame(rtr(0x000, 2), at_ms(1)));                           // RTR on NMT
  EXPECT_TRUE(s.on_frame(rtr(0x705, 2), at_ms(1)));                           // guard RTR, DLC 2
  EXPECT_TRUE(s.on_frame(make_frame(0x77F, {0x05, 0x00}), at_ms(1)));         // heartbeat DLC 2
  EXPECT_TRUE(s.on_frame(make_frame(0x77F, {0x03}), at_ms(1)));               // unknown state
  EXPECT_EQ(s.counters().malformed, 8U);

  EXPECT_TRUE(s.on_frame(make_frame(0x705, {0x05}), at_ms(2)));  // our COB-ID from someone else
  EXPECT_EQ(s.counters().unexpected, 1U);

  EXPECT_FALSE(s.on_frame(rtr(0x706), at_ms(3)));
  EXPECT_FALSE(s.on_frame(make_frame(0x605, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}), at_ms(3)));
  CanFrame ext = nmt(0x01, 0x05);
  ext.extended = true;
  EXPECT_FALSE(s.on_frame(ext, at_ms(3)));

  EXPECT_EQ(s.state(), NmtState::PreOperational);
  EXPECT_TRUE(events(s).empty());
  EXPECT_TRUE(poll(s, 3).empty());  // no reply to the DLC 2 request
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());  // the bad heartbeats did not arm the consumer
}

TEST_F(Slave, RtrWhileHeartbeatIsOnIsNotAnswered) {
  auto cfg = config();
  cfg.heartbeat_period_ms = 100;
  NmtSlave s(cfg);
  boot(s);
  EXPECT_TRUE(s.on_frame(rtr(0x705), at_ms(10)));  // SD6 §6.8: heartbeat and guarding exclude each other
  EXPECT_TRUE(poll(s, 10).empty());
  EXPECT_EQ(s.counters().unexpected, 1U);
  EXPECT_EQ(s.counters().guard_replies, 0U);
}

TEST_F(Slave, RequestBurstIsBounded) {
  NmtSlave s(config());
  boot(s);
  for (int k = 0; k < NmtSlave::kMaxPendingReplies + 2; ++k) s.on_frame(rtr(0x705), at_ms(1));
  const auto f = poll(s, 1);
  ASSERT_EQ(f.size(), NmtSlave::kMaxPendingReplies);
  EXPECT_TRUE(is_frame(f[0], 0x705, {0x7F}));
  EXPECT_TRUE(is_frame(f[1], 0x705, {0xFF}));
  EXPECT_EQ(s.counters().unexpected, 2U);
}

}  // namespace
}  // namespace drivegate::canopen::test
