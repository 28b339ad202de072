// The fixed-size latency histogram against exact percentiles of the same samples (sorted), over
// random log-uniform samples. Seed: LOOM_TEST_SEED (printed).
#include "loom/firmware/latency_histogram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

using loom::firmware::LatencyHistogram;

TEST(LatencyHistogram, BucketsTileTheRangeWithBoundedWidth) {
  for (std::size_t i = 0; i + 1 < LatencyHistogram::kBuckets; ++i) {
    ASSERT_EQ(LatencyHistogram::upper(i), LatencyHistogram::lower(i + 1)) << i;
    ASSERT_EQ(LatencyHistogram::index(LatencyHistogram::lower(i)), i);
    ASSERT_EQ(LatencyHistogram::index(LatencyHistogram::upper(i) - 1), i);
    const double width = static_cast<double>(LatencyHistogram::upper(i) - LatencyHistogram::lower(i));
    if (LatencyHistogram::lower(i) >= 64) {
      ASSERT_LE(width / static_cast<double>(LatencyHistogram::lower(i)), 1.0 / 32);
    }
  }
  EXPECT_EQ(LatencyHistogram::index(0), 0u);
  EXPECT_EQ(LatencyHistogram::index(std::uint64_t{1} << 50), LatencyHistogram::kBuckets - 1);
}

TEST(LatencyHistogram, PercentilesMatchSortedSamplesWithin3Percent) {
  const char* env = std::getenv("LOOM_TEST_SEED");
  const unsigned seed = env != nullptr ? static_cast<unsigned>(std::strtoul(env, nullptr, 10)) : 20261123u;
  std::printf("seed %u (LOOM_TEST_SEED)\n", seed);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> logv(std::log(10.0), std::log(5e6));
  for (int trial = 0; trial < 20; ++trial) {
    LatencyHistogram h;
    std::vector<std::int64_t> v(5000 + static_cast<std::size_t>(trial) * 100);
    for (auto& x : v) {
      x = static_cast<std::int64_t>(std::exp(logv(rng)));
      h.add(x);
    }
    std::sort(v.begin(), v.end());
    for (double q : {0.5, 0.9, 0.99, 0.999}) {
      const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1;
      const double exact = static_cast<double>(v[k]);
      EXPECT_NEAR(static_cast<double>(h.percentile(q)), exact, std::max(1.0, exact / 32))
          << "q " << q << " seed " << seed;
    }
    EXPECT_EQ(h.max(), v.back());
    EXPECT_EQ(h.count(), v.size());
  }
}

TEST(LatencyHistogram, SmallValuesAreExactAndEmptyIsZero) {
  LatencyHistogram h;
  EXPECT_EQ(h.percentile(0.5), 0);
  for (int i = 0; i < 10; ++i) h.add(i);  // 0..9
  EXPECT_EQ(h.percentile(0.5), 4);
  EXPECT_EQ(h.percentile(1.0), 9);
  h.add(-5);  // clamped to 0, never a negative bucket
  EXPECT_EQ(h.count(), 11u);
}
