#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "core/timing_stats.hpp"
#include "tests/support/alloc_counter.hpp"

namespace drivegate::core {
namespace {

// Exact percentile with the same rank rule as the histogram: the ceil(p/100 * n)-th smallest.
std::int64_t exact_percentile(std::vector<std::int64_t> values, double p) {
  std::sort(values.begin(), values.end());
  const auto rank = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(values.size()))));
  return values[rank - 1];
}

void expect_close(std::int64_t got, std::int64_t want, double rel) {
  const double tolerance = std::max(16.0, rel * static_cast<double>(want));
  EXPECT_NEAR(static_cast<double>(got), static_cast<double>(want), tolerance) << "want " << want;
}

TEST(LatencyHistogram, EmptyAnswersZero) {
  const LatencyHistogram h;
  EXPECT_EQ(h.count(), 0U);
  EXPECT_EQ(h.max(), 0);
  EXPECT_EQ(h.min(), 0);
  EXPECT_EQ(h.percentile(50.0), 0);
  EXPECT_EQ(h.percentile(100.0), 0);
}

TEST(LatencyHistogram, BucketsCoverEveryValueWithBoundedWidth) {
  // Walk values across the whole range (each octave densely near its edges).
  std::vector<std::int64_t> values;
  for (std::int64_t v = 0; v < 4096; ++v) values.push_back(v);
  for (unsigned bit = 12; bit < LatencyHistogram::kTopBits; ++bit) {
    const std::int64_t base = std::int64_t{1} << bit;
    for (std::int64_t d = -70; d <= 70; ++d) values.push_back(base + d);
    values.push_back(base + base / 3);
  }
  values.push_back(LatencyHistogram::kTrackedMax - 1);
  for (const std::int64_t v : values) {
    const std::size_t i = LatencyHistogram::bucket_of(v);
    ASSERT_LT(i, LatencyHistogram::kBucketCount) << v;
    const std::int64_t lower = LatencyHistogram::bucket_lower(i);
    const std::int64_t width = LatencyHistogram::bucket_width(i);
    EXPECT_LE(lower, v);
    EXPECT_LT(v, lower + width);
    EXPECT_LE(width, std::max<std::int64_t>(32, lower / 32)) << v;
  }
  // Buckets are contiguous: each starts where the previous ended.
  for (std::size_t i = 1; i < LatencyHistogram::kBucketCount; ++i) {
    EXPECT_EQ(LatencyHistogram::bucket_lower(i), LatencyHistogram::bucket_lower(i - 1) + LatencyHistogram::bucket_width(i - 1)) << i;
  }
  EXPECT_EQ(LatencyHistogram::bucket_lower(LatencyHistogram::kBucketCount - 1) +
                LatencyHistogram::bucket_width(LatencyHistogram::kBucketCount - 1),
            LatencyHistogram::kTrackedMax);
  EXPECT_EQ(LatencyHistogram::bucket_of(LatencyHistogram::kTrackedMax), LatencyHistogram::kOverflow);
}

TEST(LatencyHistogram, UniformMicrosecondsToMillisecond) {
  LatencyHistogram h;
  std::vector<std::int64_t> values;
  for (std::int64_t k = 1; k <= 1000; ++k) values.push_back(k * 1000);
  for (const auto v : values) h.record(v);
  EXPECT_EQ(h.count(), 1000U);
  EXPECT_EQ(h.max(), 1'000'000);
  EXPECT_EQ(h.min(), 1000);
  for (const double p : {1.0, 10.0, 50.0, 90.0, 99.0, 99.9}) {
    expect_close(h.percentile(p), exact_percentile(values, p), 0.02);
  }
  EXPECT_EQ(h.percentile(100.0), 1'000'000);
  EXPECT_EQ(h.percentile(0.0), 1000);
}

TEST(LatencyHistogram, LogNormalMatchesExactPercentilesWithinTwoPercent) {
  // Cycle lateness is skewed: most wake-ups a few us late, a long tail to milliseconds.
  std::mt19937_64 rng(42);
  std::lognormal_distribution<double> dist(std::log(20'000.0), 1.2);
  std::vector<std::int64_t> values;
  LatencyHistogram h;
  for (int i = 0; i < 200'000; ++i) {
    const auto v = static_cast<std::int64_t>(std::min(dist(rng), 5e8));
    values.push_back(v);
    h.record(v);
  }
  for (const double p : {50.0, 90.0, 99.0, 99.9, 99.99}) {
    expect_close(h.percentile(p), exact_percentile(values, p), 0.02);
  }
  EXPECT_EQ(h.max(), *std::max_element(values.begin(), values.end()));
}

TEST(LatencyHistogram, SingleValueIsExact) {
  LatencyHistogram h;
  h.record(123'457);
  EXPECT_EQ(h.percentile(50.0), 123'457);
  EXPECT_EQ(h.percentile(99.0), 123'457);
}

TEST(LatencyHistogram, NegativeCountsAsZeroAndHugeValuesOverflow) {
  LatencyHistogram h;
  h.record(-500);
  h.record(5'000'000'000);  // 5 s: beyond the buckets
  EXPECT_EQ(h.count(), 2U);
  EXPECT_EQ(h.min(), 0);
  EXPECT_EQ(h.max(), 5'000'000'000);
  EXPECT_EQ(h.overflow_count(), 1U);
  EXPECT_LE(h.percentile(50.0), 16);  // within the first bucket, [0, 32) ns
  EXPECT_EQ(h.percentile(100.0), 5'000'000'000);
  h.record(std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(h.max(), std::numeric_limits<std::int64_t>::max());
}

TEST(LatencyHistogram, OutOfRangePercentilesAreClamped) {
  LatencyHistogram h;
  for (std::int64_t v = 1; v <= 100; ++v) h.record(v * 10'000);
  EXPECT_EQ(h.percentile(-5.0), h.percentile(0.0));
  EXPECT_EQ(h.percentile(250.0), h.max());
  EXPECT_EQ(h.percentile(std::numeric_limits<double>::quiet_NaN()), h.percentile(0.0));
  EXPECT_EQ(h.percentile(std::numeric_limits<double>::infinity()), h.max());
}

TEST(LatencyHistogram, MergeEqualsRecordingEverythingOnce) {
  LatencyHistogram a;
  LatencyHistogram b;
  LatencyHistogram all;
  for (std::int64_t v = 0; v < 5000; ++v) {
    const std::int64_t x = (v * 7919) % 3'000'000;
    (v % 3 == 0 ? a : b).record(x);
    all.record(x);
  }
  a.merge(b);
  EXPECT_EQ(a.count(), all.count());
  EXPECT_EQ(a.max(), all.max());
  EXPECT_EQ(a.min(), all.min());
  for (const double p : {0.0, 25.0, 50.0, 99.0, 100.0}) EXPECT_EQ(a.percentile(p), all.percentile(p));

  LatencyHistogram empty;
  empty.merge(LatencyHistogram{});
  EXPECT_EQ(empty.count(), 0U);
  EXPECT_EQ(empty.min(), 0);
}

TEST(LatencyHistogram, ResetForgetsEverything) {
  LatencyHistogram h;
  h.record(1'000'000);
  h.reset();
  EXPECT_EQ(h.count(), 0U);
  EXPECT_EQ(h.max(), 0);
  h.record(2000);
  EXPECT_EQ(h.min(), 2000);
  EXPECT_EQ(h.max(), 2000);
}

TEST(LatencyHistogram, RecordAndPercentileDoNotAllocate) {
  LatencyHistogram h;
  const test::AllocationScope scope;
  for (std::int64_t v = 0; v < 10'000; ++v) h.record(v * 997);
  std::int64_t sink = h.percentile(99.0);
  h.merge(h);
  sink += h.percentile(50.0);
  h.reset();
  EXPECT_EQ(scope.count(), 0U);
  EXPECT_GT(sink, 0);
}

}  // namespace
}  // namespace drivegate::core
