// SyncProducer: 080h DLC 0 on a grid start + k * period, no drift, late polls skip instead of
// bursting.
#include <gtest/gtest.h>

#include <cstdint>

#include "adapters/canopen/master/nmt_master.hpp"
#include "tests/canopen_nmt/nmt_test_support.hpp"

namespace drivegate::canopen::test {
namespace {

TEST(SyncProducer, IdleUntilStarted) {
  SyncProducer s(0x080, milliseconds(1));
  TxQueue tx;
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());
  EXPECT_FALSE(s.poll(at_ms(0), tx));
  EXPECT_TRUE(tx.empty());
}

TEST(SyncProducer, NoDriftOverTenThousandPeriodsWithJitteredPolls) {
  // An odd period (1.000333 ms) so that any rounding or accumulation of poll times would show.
  const auto period = nanoseconds(1'000'333);
  SyncProducer s(0x080, period);
  TxQueue tx;
  s.start(at_ms(0));
  EXPECT_EQ(s.next_deadline(), at_ms(0));
  std::uint64_t lcg = 12345;
  for (std::int64_t k = 0; k < 10'000; ++k) {
    const auto deadline = at_ms(0) + k * period;
    ASSERT_EQ(s.next_deadline(), deadline) << "period " << k;
    ASSERT_FALSE(s.poll(deadline - nanoseconds(1), tx));
    // Late by up to 0.9 period: still this grid point, and the next one stays on the grid.
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    const auto jitter = nanoseconds(static_cast<std::int64_t>((lcg >> 33) % 900'000));
    ASSERT_TRUE(s.poll(deadline + jitter, tx));
    ASSERT_EQ(tx.size(), 1U);
    const CanFrame f = tx.front();
    tx.pop();
    ASSERT_EQ(f.id, 0x080U);
    ASSERT_EQ(f.dlc, 0U);  // no SYNC counter (SD6 digest §6.1, AKD part 1 §7)
    ASSERT_FALSE(f.remote);
    ASSERT_FALSE(s.poll(deadline + jitter, tx));  // one SYNC per grid point
  }
  EXPECT_EQ(s.sent(), 10'000U);
  EXPECT_EQ(s.skipped(), 0U);
  EXPECT_EQ(s.next_deadline(), at_ms(0) + 10'000 * period);
}

TEST(SyncProducer, LatePollSendsOneAndCountsTheSkipped) {
  SyncProducer s(0x080, milliseconds(2));
  TxQueue tx;
  s.start(at_ms(0));
  ASSERT_TRUE(s.poll(at_ms(0), tx));
  // Next due at 2; a poll at 9 has passed 2, 4, 6 and 8: one goes out for 8, three are skipped.
  EXPECT_TRUE(s.poll(at_ms(9), tx));
  EXPECT_EQ(drain(tx).size(), 2U);
  EXPECT_EQ(s.skipped(), 3U);
  EXPECT_EQ(s.sent(), 2U);
  EXPECT_EQ(s.next_deadline(), at_ms(10));  // still on the grid
  // Exactly one period late: the due one is skipped, the current one sent.
  EXPECT_TRUE(s.poll(at_ms(12), tx));
  EXPECT_EQ(s.skipped(), 4U);
  EXPECT_EQ(s.next_deadline(), at_ms(14));
}

TEST(SyncProducer, StopAndRestart) {
  SyncProducer s(0x080, milliseconds(1));
  TxQueue tx;
  s.start(at_ms(0));
  s.poll(at_ms(0), tx);
  s.stop();
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());
  EXPECT_FALSE(s.poll(at_ms(5), tx));
  s.start(at_ms(100) + nanoseconds(250));  // a new grid
  EXPECT_EQ(s.next_deadline(), at_ms(100) + nanoseconds(250));
  EXPECT_TRUE(s.poll(at_ms(101), tx));
  EXPECT_EQ(s.next_deadline(), at_ms(101) + nanoseconds(250));
  EXPECT_EQ(s.skipped(), 0U);
}

TEST(SyncProducer, FullQueueLosesTheSyncAndKeepsTheGrid) {
  SyncProducer s(0x080, milliseconds(1));
  TxQueue tx;
  while (tx.size() < 1024) tx.push(CanFrame{});
  s.start(at_ms(0));
  EXPECT_FALSE(s.poll(at_ms(0), tx));
  EXPECT_EQ(s.sent(), 0U);
  EXPECT_EQ(s.skipped(), 1U);
  EXPECT_EQ(s.next_deadline(), at_ms(1));
}

TEST(SyncProducer, CobIdFlagsAreNotSent) {
  SyncProducer s(0x40000080U, milliseconds(1));  // 1005h with the "generate" bit 30
  TxQueue tx;
  s.start(at_ms(0));
  ASSERT_TRUE(s.poll(at_ms(0), tx));
  EXPECT_EQ(tx.front().id, 0x080U);
  EXPECT_FALSE(tx.front().extended);
}

TEST(SyncProducer, ZeroPeriodNeverRuns) {
  SyncProducer s(0x080, core::Duration::zero());
  TxQueue tx;
  s.start(at_ms(0));
  EXPECT_EQ(s.next_deadline(), core::TimePoint::max());
  EXPECT_FALSE(s.poll(at_ms(10), tx));
}

}  // namespace
}  // namespace drivegate::canopen::test
