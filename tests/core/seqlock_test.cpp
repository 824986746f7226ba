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
  // The writer runs until the reader has made its reads, so the two overlap however the
  // threads are scheduled.
  constexpr std::uint64_t kReads = 200000;
  std::atomic<bool> reader_done{false};
  std::atomic<std::uint64_t> written{0};
  std::thread writer([&] {
    Payload p;
    for (std::uint64_t i = 1; !reader_done.load(std::memory_order_relaxed); ++i) {
      p.a = i;
      p.b = ~i;
      for (auto& x : p.c) x = i;
      lock.store(p);
      written.store(i, std::memory_order_relaxed);
    }
  });
  std::uint64_t last = 0;
  for (std::uint64_t n = 0; n < kReads; ++n) {
    const Payload p = lock.load();
    ASSERT_EQ(p.b, ~p.a);
    for (auto x : p.c) ASSERT_EQ(x, p.a);
    ASSERT_GE(p.a, last);  // never goes back in time
    last = p.a;
  }
  reader_done = true;
  writer.join();
  EXPECT_EQ(lock.load().a, written.load());
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

// A payload whose size is not a whole number of words: the last bytes travel in a partial word,
// every byte arrives and nothing beyond the payload is read.
TEST(Seqlock, CarriesPayloadsOfOddSize) {
  struct Odd {
    unsigned char bytes[21];
  };
  static_assert(sizeof(Odd) % sizeof(std::uint64_t) != 0);
  Seqlock<Odd> lock;
  Odd o{};
  for (unsigned i = 0; i < sizeof(o.bytes); ++i) o.bytes[i] = static_cast<unsigned char>(0xA0 + i);
  lock.store(o);
  const Odd r = lock.load();
  for (unsigned i = 0; i < sizeof(o.bytes); ++i) EXPECT_EQ(r.bytes[i], 0xA0 + i) << "byte " << i;
}
