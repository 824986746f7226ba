#include "core/seqlock.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "core/command.hpp"

using drivegate::core::Seqlock;

namespace {
struct Payload {
  std::uint64_t a = 0;
  std::uint64_t b = 0;
  std::uint64_t c[8] = {};
};
}  // namespace

TEST(Seqlock, ReaderNeverSeesATornValue) {
  static Seqlock<Payload> lock;
  Payload first;
  first.b = ~first.a;
  lock.store(first);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    Payload p;
    for (std::uint64_t i = 1; i < 300000; ++i) {
      p.a = i;
      p.b = ~i;
      for (auto& x : p.c) x = i;
      lock.store(p);
    }
    done = true;
  });
  std::uint64_t reads = 0;
  while (!done) {
    const Payload p = lock.load();
    ASSERT_EQ(p.b, ~p.a);
    for (auto x : p.c) ASSERT_EQ(x, p.a);
    ++reads;
  }
  writer.join();
  EXPECT_GT(reads, 0u);
  EXPECT_EQ(lock.load().a, 299999u);
}

TEST(Seqlock, CarriesAxisSnapshots) {
  Seqlock<drivegate::core::AxisSnapshot> lock;
  drivegate::core::AxisSnapshot s;
  s.position = 12.5;
  s.fault_text.assign("overcurrent");
  const auto v0 = lock.version();
  lock.store(s);
  EXPECT_EQ(lock.version(), v0 + 1);
  const auto r = lock.load();
  EXPECT_DOUBLE_EQ(r.position, 12.5);
  EXPECT_EQ(r.fault_text.view(), "overcurrent");
}
