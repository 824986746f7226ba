#pragma once
// Cycle lateness histogram (DESIGN.md §3: timing health is an output). Fixed size and
// allocation-free so the cycle thread can record into it every cycle.
//
// Buckets are log-linear like HdrHistogram: below 1024 ns one linear range, then every power of
// two [2^k, 2^(k+1)) is split into kSubBuckets equal buckets, up to 2^30 ns (~1.07 s). A bucket
// is at most 1/32 of its lower bound wide, and percentile() answers with the bucket midpoint, so
// any answer is within ~1.6 % (or 16 ns below 1 us) of a recorded value. Values above the top
// land in an overflow bucket; max() stays exact whatever the value.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace drivegate::core {

class LatencyHistogram {
 public:
  static constexpr unsigned kSubBucketBits = 5;
  static constexpr std::int64_t kSubBuckets = std::int64_t{1} << kSubBucketBits;
  static constexpr unsigned kLinearBits = 10;  // [0, 1024 ns) is one linear range
  static constexpr unsigned kTopBits = 30;     // 2^30 ns ~ 1.07 s is the top of the buckets
  static constexpr std::int64_t kTrackedMax = std::int64_t{1} << kTopBits;
  static constexpr std::size_t kBucketCount =
      static_cast<std::size_t>(kSubBuckets) * (1 + kTopBits - kLinearBits);
  static constexpr std::size_t kOverflow = kBucketCount;

  // A negative value (a wake-up before the planned time) counts as zero lateness.
  constexpr void record(std::int64_t ns) noexcept {
    const std::int64_t v = std::max<std::int64_t>(ns, 0);
    ++counts_[bucket_of(v)];
    ++count_;
    min_ = std::min(min_, v);
    max_ = std::max(max_, v);
  }

  // Value below which p percent of the recorded values fall (p in [0, 100], clamped; NaN counts
  // as 0). Returns 0 when nothing was recorded. The answer never leaves [min(), max()], and the
  // ends are exact: percentile(0) == min(), percentile(100) == max().
  [[nodiscard]] constexpr std::int64_t percentile(double p) const noexcept {
    if (count_ == 0) return 0;
    if (!(p > 0.0)) return min_;  // also catches NaN
    if (p >= 100.0) return max_;
    const double wanted = std::ceil(p / 100.0 * static_cast<double>(count_));
    const std::uint64_t rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(wanted));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < counts_.size(); ++i) {
      seen += counts_[i];
      if (seen >= rank) {
        if (i == kOverflow) return max_;
        return std::clamp(bucket_lower(i) + bucket_width(i) / 2, min_, max_);
      }
    }
    return max_;
  }

  [[nodiscard]] constexpr std::int64_t max() const noexcept { return count_ == 0 ? 0 : max_; }
  [[nodiscard]] constexpr std::int64_t min() const noexcept { return count_ == 0 ? 0 : min_; }
  [[nodiscard]] constexpr std::uint64_t count() const noexcept { return count_; }
  // Values above the tracked range (~1.07 s); they still count in percentiles, at max().
  [[nodiscard]] constexpr std::uint64_t overflow_count() const noexcept { return counts_[kOverflow]; }

  constexpr void reset() noexcept {
    counts_.fill(0);
    count_ = 0;
    min_ = std::numeric_limits<std::int64_t>::max();
    max_ = 0;
  }

  constexpr void merge(const LatencyHistogram& other) noexcept {
    for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
    count_ += other.count_;
    min_ = std::min(min_, other.min_);
    max_ = std::max(max_, other.max_);
  }

  // Bucket geometry, public so tests can check the error bound.
  [[nodiscard]] static constexpr std::size_t bucket_of(std::int64_t v) noexcept {
    if (v >= kTrackedMax) return kOverflow;
    const auto u = static_cast<std::uint64_t>(v);
    if (u < (std::uint64_t{1} << kLinearBits)) return static_cast<std::size_t>(u >> (kLinearBits - kSubBucketBits));
    const auto octave = static_cast<unsigned>(std::bit_width(u)) - 1;  // kLinearBits..kTopBits-1
    const std::uint64_t sub = (u >> (octave - kSubBucketBits)) - static_cast<std::uint64_t>(kSubBuckets);
    return static_cast<std::size_t>(kSubBuckets) * (1 + octave - kLinearBits) + static_cast<std::size_t>(sub);
  }
  [[nodiscard]] static constexpr std::int64_t bucket_lower(std::size_t i) noexcept {
    const auto sub = static_cast<std::int64_t>(i) % kSubBuckets;
    const auto group = static_cast<unsigned>(static_cast<std::int64_t>(i) / kSubBuckets);
    if (group == 0) return sub << (kLinearBits - kSubBucketBits);
    return (kSubBuckets + sub) << (kLinearBits - 1 + group - kSubBucketBits);
  }
  [[nodiscard]] static constexpr std::int64_t bucket_width(std::size_t i) noexcept {
    const auto group = static_cast<unsigned>(static_cast<std::int64_t>(i) / kSubBuckets);
    return std::int64_t{1} << (kLinearBits - kSubBucketBits + (group == 0 ? 0 : group - 1));
  }

 private:
  std::array<std::uint64_t, kBucketCount + 1> counts_{};
  std::uint64_t count_ = 0;
  std::int64_t min_ = std::numeric_limits<std::int64_t>::max();
  std::int64_t max_ = 0;
};

}  // namespace drivegate::core
