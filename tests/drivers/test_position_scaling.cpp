// SI ↔ counts and 32-bit wrap handling: one revolution is 2^20 counts, and a rotary axis running for
// longer than 2048 turns must keep an unwrapped position across the int32 wrap.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/position_scaling.hpp"

namespace loom::drivers {
namespace {

TEST(PositionScaling, OneTurnIsTwoToTheTwentyCounts) {
  EXPECT_EQ(si_to_counts(2.0 * std::numbers::pi, kDefaultCountsPerRad), 1 << 20);
  EXPECT_EQ(si_to_counts(-std::numbers::pi, kDefaultCountsPerRad), -(1 << 19));
  EXPECT_EQ(si_to_counts(0.020, kDefaultCountsPerM), 1 << 20);  // one motor turn of carriage travel
  EXPECT_DOUBLE_EQ(counts_to_si(1 << 20, kDefaultCountsPerRad), 2.0 * std::numbers::pi);
  // Round trip within half a count.
  for (double x : {0.0, 1e-6, 0.1234, -3.5, 1000.0}) {
    EXPECT_NEAR(counts_to_si(si_to_counts(x, kDefaultCountsPerRad), kDefaultCountsPerRad), x,
                0.5 / kDefaultCountsPerRad);
  }
}

TEST(PositionScaling, NonFiniteAndHugeValuesAreSafe) {
  EXPECT_EQ(si_to_counts(std::numeric_limits<double>::quiet_NaN(), 1000.0), 0);
  EXPECT_EQ(si_to_counts(std::numeric_limits<double>::infinity(), 1000.0), 0);
  EXPECT_GT(si_to_counts(1e300, 1000.0), 0);
  EXPECT_LT(si_to_counts(-1e300, 1000.0), 0);
}

TEST(PositionScaling, UnwrapsAcrossTheInt32Wrap) {
  PositionUnwrapper u;
  const std::int32_t near_top = std::numeric_limits<std::int32_t>::max() - 100;
  u.reset(near_top);
  std::int64_t expected = near_top;
  // Forward through the wrap in steps of 37 counts, then back again.
  for (int i = 0; i < 10; ++i) {
    expected += 37;
    EXPECT_EQ(u.update(wire_counts(expected)), expected);
  }
  EXPECT_GT(expected, std::numeric_limits<std::int32_t>::max());
  for (int i = 0; i < 20; ++i) {
    expected -= 37;
    EXPECT_EQ(u.update(wire_counts(expected)), expected);
  }
  // 3000 turns at 2^20 counts/turn: far beyond int32, still exact.
  u.reset(0);
  for (int turn = 1; turn <= 3000; ++turn) u.update(wire_counts(static_cast<std::int64_t>(turn) << 20));
  EXPECT_EQ(u.value(), static_cast<std::int64_t>(3000) << 20);
}

TEST(PositionScaling, WireCountsAreTheLowThirtyTwoBits) {
  EXPECT_EQ(wire_counts(0x1'0000'0005LL), 5);
  EXPECT_EQ(wire_counts(-1), -1);
  EXPECT_EQ(wire_counts(0x8000'0000LL), std::numeric_limits<std::int32_t>::min());
}

}  // namespace
}  // namespace loom::drivers
