// The NMT master against simulated slaves on one in-process wire, in virtual time: guarding both
// ways (node guarding at the master, life guarding at the slave), heartbeat both ways (the
// master consumes the slave's, the slave consumes the master's), losses and recoveries.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <vector>

#include "adapters/canopen/master/nmt_master.hpp"
#include "adapters/canopen/sim/nmt_slave.hpp"
#include "tests/canopen_nmt/nmt_test_support.hpp"

namespace drivegate::canopen::test {
namespace {

constexpr NodeId kNode = 5;
constexpr NodeId kMasterNode = 127;

struct MasterEvents {
  std::vector<NmtEvent> all;
  void collect(NmtMaster& m) {
    NmtEvent e;
    while (m.next_event(e)) all.push_back(e);
  }
  [[nodiscard]] std::size_t count(NmtEventKind k) const {
    std::size_t n = 0;
    for (const auto& e : all) n += e.kind == k ? 1U : 0U;
    return n;
  }
};

struct SlaveEvents {
  std::vector<std::pair<core::TimePoint, sim::NmtSlaveEvent>> all;
  [[nodiscard]] std::optional<core::TimePoint> first(sim::NmtSlaveEventKind k) const {
    for (const auto& [t, e] : all) {
      if (e.kind == k) return t;
    }
    return std::nullopt;
  }
};

// One master and one slave on a wire. Events are collected as they happen, with their time.
class Loop {
 public:
  Loop(NmtMasterConfig mcfg, NmtNodeConfig node, sim::NmtSlaveConfig scfg)
      : nodes_{node}, master_(mcfg, nodes_), slave_(scfg) {
    master_idx_ = wire_.add({[this](core::TimePoint t, TxQueue& tx) {
                               master_.poll(t, tx);
                               master_events.collect(master_);
                             },
                             [this](const CanFrame& f, core::TimePoint t) {
                               master_.on_frame(f, t);
                               master_events.collect(master_);
                             },
                             [this] { return master_.next_deadline(); }});
    slave_idx_ = wire_.add({[this](core::TimePoint t, TxQueue& tx) {
                              slave_.poll(t, tx);
                              collect_slave(t);
                            },
                            [this](const CanFrame& f, core::TimePoint t) {
                              slave_.on_frame(f, t);
                              collect_slave(t);
                            },
                            [this] { return slave_.next_deadline(); }});
    wire_.start(at_ms(0));
    slave_.power_on(at_ms(0));
  }

  void master_command(NmtCommand cs) {
    TxQueue tx;
    ASSERT_TRUE(master_.command(cs, kNode, tx));
    while (!tx.empty()) {
      slave_.on_frame(tx.front(), wire_.now());
      tx.pop();
    }
    collect_slave(wire_.now());
  }
  void kill_master() { wire_[master_idx_].alive = false; }
  [[nodiscard]] core::TimePoint last_sent_by(std::uint32_t id, bool remote) const {
    core::TimePoint last{};
    for (const auto& [t, f] : wire_.log) {
      if (f.id == id && f.remote == remote) last = t;
    }
    return last;
  }

  Wire wire_;
  std::array<NmtNodeConfig, 1> nodes_;
  NmtMaster master_;
  sim::NmtSlave slave_;
  MasterEvents master_events;
  SlaveEvents slave_events;

 private:
  void collect_slave(core::TimePoint t) {
    sim::NmtSlaveEvent e;
    while (slave_.next_event(e)) slave_events.all.emplace_back(t, e);
  }
  std::size_t master_idx_ = 0;
  std::size_t slave_idx_ = 0;
};

NmtMasterConfig master_config(core::Duration heartbeat) {
  NmtMasterConfig c;
  c.own_node = kMasterNode;
  c.heartbeat_period = heartbeat;
  return c;
}

NmtNodeConfig guarded() {
  NmtNodeConfig n;
  n.node = kNode;
  n.watch = Watch::Guarding;
  n.guard_time = milliseconds(100);
  n.life_time_factor = 3;
  return n;
}

sim::NmtSlaveConfig guarded_slave(bool sd6) {
  sim::NmtSlaveConfig s;
  s.node = kNode;
  s.guard_time_ms = 100;  // SD6 D-5: 1017h = 0, 100Ch = 100, 100Dh = 3
  s.life_time_factor = 3;
  s.options.life_guarding_only_operational = sd6;
  return s;
}

TEST(GuardingLoop, RunsCleanThenTheSlaveNoticesADeadMaster) {
  Loop l(master_config(core::Duration::zero()), guarded(), guarded_slave(false));
  l.wire_.run_until(at_ms(5));
  ASSERT_EQ(l.master_events.count(NmtEventKind::BootUp), 1U);
  EXPECT_EQ(l.master_.state(kNode), NmtState::PreOperational);
  l.master_command(NmtCommand::Start);
  l.master_.watch(kNode, l.wire_.now());
  l.wire_.run_until(at_ms(3000));
  EXPECT_EQ(l.master_.state(kNode), NmtState::Operational);
  EXPECT_FALSE(l.master_.lost(kNode));
  EXPECT_EQ(l.master_.counters().toggle_errors, 0U);
  EXPECT_GE(l.master_.counters().guard_replies, 29U);
  EXPECT_FALSE(l.slave_events.first(sim::NmtSlaveEventKind::LifeGuarding));

  // Kill the master: its last RTR plus guard time x factor is when the slave's life guarding fires.
  l.kill_master();
  const auto last_rtr = l.last_sent_by(0x705, true);
  l.wire_.run_until(at_ms(5000));
  const auto fired = l.slave_events.first(sim::NmtSlaveEventKind::LifeGuarding);
  ASSERT_TRUE(fired);
  EXPECT_EQ(*fired, last_rtr + milliseconds(300));
  EXPECT_EQ(l.slave_.counters().life_guarding, 1U);
}

TEST(GuardingLoop, LifeGuardingInPreOperationalDependsOnThePersona) {
  for (const bool sd6 : {false, true}) {
    Loop l(master_config(core::Duration::zero()), guarded(), guarded_slave(sd6));
    l.wire_.run_until(at_ms(5));
    l.master_.watch(kNode, l.wire_.now());  // guarded while still pre-operational
    l.wire_.run_until(at_ms(1000));
    EXPECT_EQ(l.master_.state(kNode), NmtState::PreOperational);
    l.kill_master();
    l.wire_.run_until(at_ms(2000));
    // AKD F129 in any state; SD6 fault 52 cause 1 only in Operational (SD6 §6.8, quirk 8).
    EXPECT_EQ(l.slave_events.first(sim::NmtSlaveEventKind::LifeGuarding).has_value(), !sd6) << "sd6=" << sd6;
    EXPECT_EQ(l.slave_.counters().life_guarding, 1U);
  }
}

TEST(GuardingLoop, SilentSlaveIsLostThenRecovers) {
  Loop l(master_config(core::Duration::zero()), guarded(), guarded_slave(false));
  l.wire_.run_until(at_ms(5));
  l.master_command(NmtCommand::Start);
  l.master_.watch(kNode, l.wire_.now());
  l.wire_.run_until(at_ms(1000));
  l.slave_.set_silent(true);
  l.wire_.run_until(at_ms(1250));
  EXPECT_FALSE(l.master_.lost(kNode));
  l.wire_.run_until(at_ms(1500));
  EXPECT_TRUE(l.master_.lost(kNode));
  EXPECT_EQ(l.master_events.count(NmtEventKind::Lost), 1U);
  l.slave_.set_silent(false);
  l.wire_.run_until(at_ms(2000));
  EXPECT_FALSE(l.master_.lost(kNode));
  EXPECT_EQ(l.master_events.count(NmtEventKind::Recovered), 1U);
  // Cut off, the slave answered nothing, so its toggle goes on where the master's expectation
  // stopped: no toggle error after the recovery.
  EXPECT_EQ(l.master_.counters().toggle_errors, 0U);
}

TEST(GuardingLoop, ResetNodeBootsAndGuardingResumesWithoutToggleError) {
  Loop l(master_config(core::Duration::zero()), guarded(), guarded_slave(false));
  l.wire_.run_until(at_ms(5));
  l.master_command(NmtCommand::Start);
  l.master_.watch(kNode, l.wire_.now());
  l.wire_.run_until(at_ms(250));  // three replies: the slave's toggle is at 1
  l.master_command(NmtCommand::ResetNode);
  l.wire_.run_until(at_ms(260));
  EXPECT_EQ(l.master_events.count(NmtEventKind::BootUp), 2U);
  EXPECT_EQ(l.master_.state(kNode), NmtState::PreOperational);
  l.master_.watch(kNode, l.wire_.now());  // reconfigured
  l.wire_.run_until(at_ms(1000));
  EXPECT_EQ(l.master_.counters().toggle_errors, 0U);
  EXPECT_FALSE(l.master_.lost(kNode));
  EXPECT_EQ(l.master_.state(kNode), NmtState::PreOperational);
}

TEST(HeartbeatLoop, BothSidesConsumeAndNoticeSilence) {
  NmtNodeConfig node;
  node.node = kNode;
  node.watch = Watch::Heartbeat;
  node.heartbeat_timeout = milliseconds(300);
  sim::NmtSlaveConfig s;
  s.node = kNode;
  s.heartbeat_period_ms = 100;
  s.heartbeat_consumer = (std::uint32_t{kMasterNode} << 16) | 250U;  // AKD §16 step 10, vector 22
  Loop l(master_config(milliseconds(100)), node, s);
  l.wire_.run_until(at_ms(5));
  l.master_command(NmtCommand::Start);
  l.master_.watch(kNode, l.wire_.now());
  l.wire_.run_until(at_ms(3000));
  EXPECT_FALSE(l.master_.lost(kNode));
  EXPECT_EQ(l.master_.state(kNode), NmtState::Operational);
  EXPECT_FALSE(l.slave_events.first(sim::NmtSlaveEventKind::HeartbeatLost));

  // The master's heartbeat stops: the slave reports it 250 ms after the last one (AKD F129).
  l.kill_master();
  const auto last_master_hb = l.last_sent_by(0x77F, false);
  l.wire_.run_until(at_ms(4000));
  const auto lost = l.slave_events.first(sim::NmtSlaveEventKind::HeartbeatLost);
  ASSERT_TRUE(lost);
  EXPECT_EQ(*lost, last_master_hb + milliseconds(250));
}

TEST(HeartbeatLoop, MasterLosesASilentSlaveAtTheTimeout) {
  NmtNodeConfig node;
  node.node = kNode;
  node.watch = Watch::Heartbeat;
  node.heartbeat_timeout = milliseconds(300);
  sim::NmtSlaveConfig s;
  s.node = kNode;
  s.heartbeat_period_ms = 100;
  Loop l(master_config(milliseconds(100)), node, s);
  l.wire_.run_until(at_ms(5));
  l.master_.watch(kNode, l.wire_.now());
  l.wire_.run_until(at_ms(1000));
  l.slave_.set_silent(true);
  const auto last_slave_hb = l.last_sent_by(0x705, false);
  l.wire_.run_until(last_slave_hb + milliseconds(300) - nanoseconds(1));
  EXPECT_FALSE(l.master_.lost(kNode));
  l.wire_.run_until(last_slave_hb + milliseconds(300));
  EXPECT_TRUE(l.master_.lost(kNode));
  l.slave_.set_silent(false);
  l.wire_.run_until(at_ms(2000));
  EXPECT_FALSE(l.master_.lost(kNode));
  EXPECT_EQ(l.master_events.count(NmtEventKind::Lost), 1U);
  EXPECT_EQ(l.master_events.count(NmtEventKind::Recovered), 1U);
}

}  // namespace
}  // namespace drivegate::canopen::test
