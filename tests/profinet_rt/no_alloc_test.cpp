// The cyclic path allocates nothing (DESIGN.md §3): 1000 provider slots (some missed) and 1000
// input frames (valid, repeated, bad IOPS), a watchdog expiry and a re-arm, with the allocation
// counter armed (tests/support/alloc_counter.hpp). The frames are built before the scope.
#include <gtest/gtest.h>

#include "tests/profinet_rt/rt_fixture.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::profinet::test {
namespace {

TEST(PnRtNoAlloc, ProviderAndConsumerCycles) {
  RtProvider p(iocr(kOutputFrameId));
  RtConsumer c(iocr(kInputFrameId));
  const Bytes good = input_frame({});
  const Bytes bad_iops = input_frame({.sensor_iops = iox_status::kBadByDevice});
  Bytes frame = good;
  constexpr std::size_t counter_at = 20 + 40;  // the cycle counter behind the tagged header and the C_SDU
  std::array<std::uint8_t, kMaxFrameSize> out{};
  core::TimePoint now{std::chrono::seconds(1)};

  const drivegate::test::AllocationScope scope;
  p.start(now);
  c.arm(now);
  std::size_t sent = 0;
  for (std::uint16_t n = 1; n <= 1000; ++n) {
    now += p.period();
    if (n % 100 != 0 && p.poll(now, out) > 0) ++sent;  // every 100th slot missed
    frame = n % 10 == 0 ? bad_iops : good;                  // same size: no reallocation
    frame[counter_at] = static_cast<std::uint8_t>(n >> 8);
    frame[counter_at + 1] = static_cast<std::uint8_t>(n);
    (void)c.on_frame(frame, now);
    (void)c.on_frame(frame, now);  // repeated
    (void)p.set_iops(kDrive, c.iops(kDrive));
  }
  EXPECT_TRUE(c.poll(now + c.data_hold_time()));
  c.arm(now);
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_EQ(sent, 990U);
  EXPECT_EQ(p.counters().missed_slots, 9U);  // the 1000th is still due
  EXPECT_EQ(c.counters().frames, 1000U);
  EXPECT_EQ(c.counters().repeated_cycle, 1000U);
  EXPECT_EQ(c.counters().timeouts, 1U);
}

}  // namespace
}  // namespace drivegate::profinet::test
