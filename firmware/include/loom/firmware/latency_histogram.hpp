// A fixed-size log-linear histogram of nanosecond durations (the loop's wake-up latency and tick cost):
// percentiles without storing samples and without allocating, so the RT loop may add to it every tick.
// Values below 64 ns are exact; above, each power-of-two octave has 32 buckets, so a reported
// percentile is within 1/32 (3 %) of the true sample value. Range: up to 2^40 ns (18 minutes).
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace loom::firmware {

class LatencyHistogram {
 public:
  static constexpr int kSubBits = 5;                        // 32 buckets per octave
  static constexpr std::uint64_t kLinear = 2u << kSubBits;  // values below this are exact (64)
  static constexpr int kMaxExp = 40;
  static constexpr std::size_t kBuckets = kLinear + (kMaxExp - kSubBits) * (1u << kSubBits);

  // RT-safe. Negative values count as 0, values beyond the range as the last bucket.
  void add(std::int64_t ns) noexcept {
    ++bins_[index(ns < 0 ? 0 : static_cast<std::uint64_t>(ns))];
    ++count_;
    if (ns > max_) max_ = ns;
  }

  // Any thread that owns the histogram (not RT: scans every bucket). The smallest value v such that at
  // least a fraction q of the samples are <= v, reported as the middle of v's bucket (exact below 64).
  std::int64_t percentile(double q) const noexcept {
    if (count_ == 0) return 0;
    const double want_d = q * static_cast<double>(count_);
    std::uint64_t want = static_cast<std::uint64_t>(want_d);
    if (static_cast<double>(want) < want_d) ++want;
    if (want == 0) want = 1;
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBuckets; ++i) {
      seen += bins_[i];
      if (seen >= want) {
        const std::int64_t mid = static_cast<std::int64_t>((lower(i) + upper(i)) / 2);
        return mid < max_ ? mid : max_;  // never report more than was seen
      }
    }
    return max_;
  }
  std::int64_t max() const noexcept { return max_; }
  std::uint64_t count() const noexcept { return count_; }

  // The bucket a value falls in, and its bounds [lower, upper) — public for the tests.
  static std::size_t index(std::uint64_t v) noexcept {
    if (v < kLinear) return static_cast<std::size_t>(v);
    const int exp = static_cast<int>(std::bit_width(v)) - 1;  // >= kSubBits + 1
    if (exp >= kMaxExp + 1) return kBuckets - 1;
    const std::uint64_t sub = (v >> (exp - kSubBits)) & ((1u << kSubBits) - 1);
    return static_cast<std::size_t>(kLinear +
                                    static_cast<std::uint64_t>(exp - kSubBits - 1) * (1u << kSubBits) + sub);
  }
  static std::uint64_t lower(std::size_t i) noexcept {
    if (i < kLinear) return i;
    const std::uint64_t k = i - kLinear;
    const int exp = static_cast<int>(k >> kSubBits) + kSubBits + 1;
    const std::uint64_t sub = k & ((1u << kSubBits) - 1);
    return (std::uint64_t{1} << exp) + (sub << (exp - kSubBits));
  }
  static std::uint64_t upper(std::size_t i) noexcept {
    if (i < kLinear) return i + 1;
    const int exp = static_cast<int>((i - kLinear) >> kSubBits) + kSubBits + 1;
    return lower(i) + (std::uint64_t{1} << (exp - kSubBits));
  }

 private:
  std::array<std::uint64_t, kBuckets> bins_{};
  std::uint64_t count_ = 0;
  std::int64_t max_ = 0;
};

}  // namespace loom::firmware
