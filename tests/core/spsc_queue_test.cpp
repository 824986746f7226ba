#include "core/spsc_queue.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <thread>

#include "tests/support/alloc_counter.hpp"

using drivegate::core::SpscQueue;

TEST(SpscQueue, FullQueueRefusesAndEmptyQueueYieldsNothing) {
  SpscQueue<int, 4> q;
  int v = 0;
  EXPECT_FALSE(q.pop(v));
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(q.push(i));
  EXPECT_FALSE(q.push(99));
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(q.pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(q.pop(v));
}

TEST(SpscQueue, PushAndPopNeverAllocate) {
  SpscQueue<std::uint64_t, 8> q;
  drivegate::test::AllocationScope scope;
  std::uint64_t v = 0;
  for (int round = 0; round < 100; ++round) {
    q.push(1);
    q.pop(v);
  }
  EXPECT_EQ(scope.count(), 0u);
}

TEST(SpscQueue, TwoThreadsTransferEveryItemInOrder) {
  static SpscQueue<std::uint64_t, 64> q;
  constexpr std::uint64_t kItems = 200000;
  std::thread producer([] {
    for (std::uint64_t i = 1; i <= kItems;)
      if (q.push(i)) ++i;
  });
  std::uint64_t expected = 1;
  std::uint64_t v = 0;
  while (expected <= kItems) {
    if (q.pop(v)) {
      ASSERT_EQ(v, expected);
      ++expected;
    }
  }
  producer.join();
}
