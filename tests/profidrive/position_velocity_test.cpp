// The velocity derived from XIST_A for telegrams without NIST_A (profiles/profidrive/position_velocity.hpp).
#include "profiles/profidrive/position_velocity.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace drivegate::profidrive {
namespace {

using namespace std::chrono_literals;

TEST(PositionVelocity, SlopeOverTheWindowAcrossTheCountersWrap) {
  PositionVelocity v(2.0);  // 2 native units per count/s
  core::TimePoint t{};
  EXPECT_EQ(v.add(INT32_MAX - 5, t), 0);  // one sample: no slope yet
  t += 16ms;
  // XIST_A wrapped: 10 counts in 16 ms, not -2^32 + 10.
  EXPECT_EQ(v.add(INT32_MIN + 4, t), 1250);
  // The slope spans the window (4 telegrams), so one telegram 4 ms late moves it less than it
  // would move the last interval's slope (10 counts in 20 ms: 1000).
  t += 20ms;
  EXPECT_EQ(v.add(INT32_MIN + 14, t), static_cast<std::int32_t>(20.0 / 0.036 * 2.0));
  t += 16ms;
  EXPECT_EQ(v.add(INT32_MIN + 24, t), static_cast<std::int32_t>(30.0 / 0.052 * 2.0));
  // The oldest sample leaves the window: 16 + 20 + 16 ms.
  t += 16ms;
  EXPECT_EQ(v.add(INT32_MIN + 34, t), static_cast<std::int32_t>(30.0 / 0.052 * 2.0));
  t += 16ms;
  EXPECT_EQ(v.add(INT32_MIN + 44, t), 1250);
}

TEST(PositionVelocity, ResetStartsAfreshAndTheRangeSaturates) {
  PositionVelocity v(1e6);
  core::TimePoint t{};
  (void)v.add(0, t);
  t += 1ms;
  EXPECT_EQ(v.add(1'000'000, t), INT32_MAX);
  v.reset();
  t += 1s;
  EXPECT_EQ(v.add(5, t), 0);  // a lost drive's last position is not a slope
  t += 1ms;
  EXPECT_EQ(v.add(-1'000'000, t), INT32_MIN);
}

}  // namespace
}  // namespace drivegate::profidrive
