// EmcyProducer: byte-exact EMCY frames, the 1015h inhibit time, the bounded queue and the NMT gate.
#include "adapters/canopen/sim/emcy_producer.hpp"

#include <gtest/gtest.h>

#include "tests/canopen_nmt/nmt_test_support.hpp"

namespace drivegate::canopen::test {
namespace {

using sim::EmcyProducer;
using sim::EmcyProducerConfig;

// SD6 D-7: life-guarding fault, event 52 cause 1.
constexpr Emcy kLifeGuarding{0x7500, 0x10, {0x34, 0x01, 0x00, 0x00, 0x00}};
// SD6 TV-5: leaving the fault state, event 30 "inactive".
constexpr Emcy kInactive{0x0000, 0x00, {0x1E, 0x00, 0x00, 0x00, 0x00}};

TEST(EmcyProducer, SendsByteExactFrames) {
  EmcyProducer p({5, 0});
  TxQueue tx;
  p.set_enabled(true);
  EXPECT_EQ(p.next_deadline(), core::TimePoint::max());
  ASSERT_TRUE(p.raise(kLifeGuarding));
  ASSERT_TRUE(p.raise(kInactive));
  p.poll(at_ms(0), tx);  // no inhibit time: both at once
  const auto f = drain(tx);
  ASSERT_EQ(f.size(), 2U);
  EXPECT_TRUE(is_frame(f[0], 0x085, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00, 0x00}));
  EXPECT_TRUE(is_frame(f[1], 0x085, {0x00, 0x00, 0x00, 0x1E, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(p.counters().sent, 2U);
  EXPECT_EQ(p.next_deadline(), core::TimePoint::max());
}

TEST(EmcyProducer, InhibitTimeSpacesFrames) {
  EmcyProducer p({5, 100});  // 1015h = 100 x 100 us = 10 ms
  TxQueue tx;
  p.set_enabled(true);
  for (int k = 0; k < 3; ++k) p.raise(kLifeGuarding);
  p.poll(at_ms(0), tx);
  EXPECT_EQ(drain(tx).size(), 1U);
  EXPECT_EQ(p.next_deadline(), at_ms(10));
  p.poll(at_ms(10) - nanoseconds(1), tx);
  EXPECT_TRUE(tx.empty());
  p.poll(at_ms(10), tx);
  EXPECT_EQ(drain(tx).size(), 1U);
  EXPECT_EQ(p.next_deadline(), at_ms(20));
  p.set_inhibit_time(5);  // written by the SDO server: 0.5 ms from the last one
  EXPECT_EQ(p.next_deadline(), at_ms(10) + std::chrono::microseconds(500));
  p.poll(at_ms(11), tx);
  EXPECT_EQ(drain(tx).size(), 1U);
  EXPECT_EQ(p.pending(), 0U);
  // An EMCY raised after a quiet spell goes at once.
  p.raise(kInactive);
  EXPECT_EQ(p.next_deadline(), at_ms(11) + std::chrono::microseconds(500));
  p.poll(at_ms(100), tx);
  EXPECT_EQ(drain(tx).size(), 1U);
}

TEST(EmcyProducer, QueueIsBounded) {
  EmcyProducer p({5, 10});
  p.set_enabled(true);
  for (std::size_t k = 0; k < EmcyProducer::kQueueCapacity; ++k) EXPECT_TRUE(p.raise(kLifeGuarding));
  EXPECT_FALSE(p.raise(kLifeGuarding));
  EXPECT_EQ(p.counters().dropped, 1U);
  EXPECT_EQ(p.pending(), EmcyProducer::kQueueCapacity);
}

TEST(EmcyProducer, NotServedMeansSuppressedAndDisablingDropsTheQueue) {
  EmcyProducer p({5, 0});
  TxQueue tx;
  EXPECT_FALSE(p.raise(kLifeGuarding));  // not enabled yet (Initialising / Stopped)
  EXPECT_EQ(p.counters().suppressed, 1U);
  p.set_enabled(true);
  p.raise(kLifeGuarding);
  p.set_enabled(false);  // NMT Stop before it went out
  p.set_enabled(true);
  p.poll(at_ms(0), tx);
  EXPECT_TRUE(tx.empty());

  EmcyProducer off({0, 0});  // node-ID 0: EMCY off, it would collide with SYNC (SD6 §6.9)
  off.set_enabled(true);
  EXPECT_FALSE(off.raise(kLifeGuarding));
  off.poll(at_ms(0), tx);
  EXPECT_TRUE(tx.empty());
}

TEST(EmcyProducer, ResetRestoresTheInhibitTimeAndEmptiesTheQueue) {
  EmcyProducer p({5, 100});
  TxQueue tx;
  p.set_enabled(true);
  p.set_inhibit_time(1000);
  p.raise(kLifeGuarding);
  p.poll(at_ms(0), tx);
  p.raise(kLifeGuarding);
  p.reset();
  EXPECT_EQ(p.inhibit_time(), 100);
  EXPECT_EQ(p.pending(), 0U);
  p.raise(kInactive);
  EXPECT_EQ(p.next_deadline(), core::TimePoint::min());  // nothing sent since the reset
}

TEST(EmcyProducer, FullTxQueueRetries) {
  EmcyProducer p({5, 0});
  TxQueue tx;
  while (tx.size() < 1024) tx.push(CanFrame{});
  p.set_enabled(true);
  p.raise(kLifeGuarding);
  p.poll(at_ms(0), tx);
  EXPECT_EQ(p.counters().tx_full, 1U);
  EXPECT_EQ(p.pending(), 1U);
  tx.clear();
  p.poll(at_ms(1), tx);
  ASSERT_EQ(tx.size(), 1U);
  EXPECT_TRUE(is_frame(tx.front(), 0x085, {0x00, 0x75, 0x10, 0x34, 0x01, 0x00, 0x00, 0x00}));
}

}  // namespace
}  // namespace drivegate::canopen::test
