// Phase table: exact at the samples, fourth-order convergent between them, and safe at the wrap and
// for non-finite input.
#include "loom/motion/phase_table.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/angles.hpp"

using namespace loom::motion;

namespace {
PhaseTable::Exact wave(double p) {
  return {std::sin(p) + 0.3 * std::cos(3 * p), std::cos(p) - 0.9 * std::sin(3 * p)};
}
double max_err(std::size_t n) {
  const PhaseTable t(n, wave);
  double e = 0;
  for (int i = 0; i < 10007; ++i) {
    const double p = kTwoPi * i / 10007.0;
    e = std::max(e, std::abs(t.at(p).value - wave(p).value));
  }
  return e;
}
}  // namespace

TEST(PhaseTable, ExactAtSamplesAndPeriodic) {
  const PhaseTable t(64, wave);
  for (int i = 0; i < 64; ++i) {
    const double p = kTwoPi * i / 64.0;
    EXPECT_NEAR(t.at(p).value, wave(p).value, 1e-14);
    EXPECT_NEAR(t.at(p + 5 * kTwoPi).value, wave(p).value, 1e-12);
    EXPECT_NEAR(t.at(p - 3 * kTwoPi).value, wave(p).value, 1e-12);
  }
  EXPECT_NEAR(t.at(std::nextafter(kTwoPi, 0.0)).value, wave(0).value, 1e-12);
}

TEST(PhaseTable, ErrorConvergesAtFourthOrder) {
  const double e1 = max_err(128), e2 = max_err(256);
  EXPECT_GT(e1 / e2, 12.0);  // ideal 16
  EXPECT_LT(e2, 1e-6);
}

TEST(PhaseTable, NonFinitePhaseNeverYieldsNaN) {
  const PhaseTable t(64, wave);
  EXPECT_TRUE(std::isfinite(t.at(std::nan("")).value));
  EXPECT_TRUE(std::isfinite(t.at(INFINITY).value));
}
