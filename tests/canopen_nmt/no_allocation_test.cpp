// on_frame / poll / next_deadline of every engine here run on the bus cycle thread: prove that they
// never allocate, including on bad input, losses, resets and EMCY text formatting.
#include <gtest/gtest.h>

#include <array>
#include <cstddef>

#include "adapters/canopen/master/emcy_consumer.hpp"
#include "adapters/canopen/master/nmt_master.hpp"
#include "adapters/canopen/sim/emcy_producer.hpp"
#include "adapters/canopen/sim/nmt_slave.hpp"
#include "tests/canopen_nmt/nmt_test_support.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::canopen::test {
namespace {

TEST(NoAllocation, MasterAndSlaveEnginesOverALongRun) {
  NmtMasterConfig mcfg;
  mcfg.heartbeat_period = milliseconds(100);
  NmtNodeConfig guarded{5, Watch::Guarding, milliseconds(300), milliseconds(20), 3};
  NmtNodeConfig beating{6, Watch::Heartbeat, milliseconds(300), milliseconds(100), 3};
  const std::array nodes{guarded, beating};
  NmtMaster master(mcfg, nodes);
  SyncProducer sync(0x080, milliseconds(1));

  sim::NmtSlaveConfig g;
  g.node = 5;
  g.guard_time_ms = 20;
  g.life_time_factor = 3;
  sim::NmtSlaveConfig h;
  h.node = 6;
  h.heartbeat_period_ms = 50;
  h.heartbeat_consumer = (127U << 16) | 250U;
  sim::NmtSlave slave_g(g);
  sim::NmtSlave slave_h(h);
  sim::EmcyProducer emcy_out({6, 10});

  constexpr std::array texts{cia402::FaultText{0x7500, "communication"}};
  constexpr std::array fields{EmcyField{3, "event"}, EmcyField{4, "cause"}};
  const std::array emcy_nodes{EmcyNodeConfig{6, texts, fields, true}};
  EmcyConsumer emcy_in(emcy_nodes);

  TxQueue master_tx;
  TxQueue slave_tx;
  NmtEvent me;
  sim::NmtSlaveEvent se;
  EmcyReport report;
  std::size_t frames = 0;
  const auto deliver_to_slaves = [&](core::TimePoint t) {
    while (!master_tx.empty()) {
      slave_g.on_frame(master_tx.front(), t);
      slave_h.on_frame(master_tx.front(), t);
      master_tx.pop();
      ++frames;
    }
  };
  const auto deliver_to_master = [&](core::TimePoint t) {
    while (!slave_tx.empty()) {
      master.on_frame(slave_tx.front(), t);
      emcy_in.on_frame(slave_tx.front(), t);
      slave_tx.pop();
      ++frames;
    }
  };

  drivegate::test::AllocationScope scope;
  slave_g.power_on(at_ms(0));
  slave_h.power_on(at_ms(0));
  sync.start(at_ms(0));
  for (std::int64_t ms = 0; ms < 3000; ++ms) {
    const auto t = at_ms(ms);
    if (ms == 10) {
      master.command(NmtCommand::Start, 0, master_tx);
      master.watch(5, t);
      master.watch(6, t);
    }
    if (ms == 1000) slave_g.set_silent(true);  // lost, with misses
    if (ms == 1500) slave_g.set_silent(false);  // recovered
    if (ms == 2000) master.command(NmtCommand::ResetNode, 6, master_tx);  // boot-up, toggle reset
    if (ms % 97 == 0) {
      emcy_out.raise(Emcy{0x7500, 0x10, {0x34, 0x01, 0, 0, 0}});
      emcy_out.raise(Emcy{0x0000, 0x00, {0x1E, 0, 0, 0, 0}});
    }
    // Bad input of every kind on the way.
    master.on_frame(make_frame(0x705, {0x03}), t);
    master.on_frame(rtr(0x705), t);
    master.on_frame(make_frame(0x720, {0x05}), t);
    emcy_in.on_frame(make_frame(0x085, {0x00}), t);
    emcy_in.on_frame(make_frame(0x0A0, {0x00, 0x75, 0x10}), t);
    slave_g.on_frame(make_frame(0x000, {0x01}), t);
    slave_g.on_frame(rtr(0x705, 5), t);

    master.poll(t, master_tx);
    sync.poll(t, master_tx);
    (void)master.next_deadline();
    (void)sync.next_deadline();
    deliver_to_slaves(t);
    slave_g.poll(t, slave_tx);
    slave_h.poll(t, slave_tx);
    emcy_out.set_enabled(slave_h.serves(sim::NmtService::Emcy));
    emcy_out.poll(t, slave_tx);
    (void)slave_g.next_deadline();
    (void)slave_h.next_deadline();
    (void)emcy_out.next_deadline();
    deliver_to_master(t);
    // Drain only now and then, as a slow control plane would.
    if (ms % 500 == 0) {
      while (master.next_event(me)) {
      }
      while (emcy_in.next_report(report)) {
      }
      while (slave_g.next_event(se)) {
      }
      while (slave_h.next_event(se)) {
      }
    }
  }
  const std::size_t allocations = scope.count();
  EXPECT_EQ(allocations, 0U);

  // The run did what it is meant to exercise.
  EXPECT_GT(frames, 3000U);
  EXPECT_GE(master.counters().losses, 1U);
  EXPECT_GE(master.counters().boot_ups, 3U);
  EXPECT_GT(master.counters().malformed, 0U);
  EXPECT_GT(master.counters().unexpected, 0U);
  EXPECT_GT(emcy_in.counters().received, 0U);
  EXPECT_GT(slave_g.counters().guard_replies, 0U);
  EXPECT_GT(slave_g.counters().life_guarding, 0U);
  EXPECT_EQ(sync.sent(), 3000U);
}

}  // namespace
}  // namespace drivegate::canopen::test
