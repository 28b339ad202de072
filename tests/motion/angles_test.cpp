// wrap_two_pi against libm's fmod (the independent truth): bit for bit on random angles across the
// unwrapped range a loom reaches (a crank turning for years), at and around multiples of 2π where the
// quotient's rounding bites, and on the special values.
#include "loom/motion/angles.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

using loom::motion::kTwoPi;
using loom::motion::wrap_two_pi;

namespace {
// The definition wrap_two_pi keeps: fmod, shifted into [0, 2π).
double reference(double a) {
  double r = std::fmod(a, kTwoPi);
  if (r < 0.0) r += kTwoPi;
  return r >= kTwoPi ? 0.0 : r;
}
bool same_bits(double x, double y) {
  return std::memcmp(&x, &y, sizeof x) == 0 || (std::isnan(x) && std::isnan(y));
}
}  // namespace

TEST(Angles, WrapTwoPiIsFmodBitForBit) {
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 2'000'000; ++i) {
    const double scale = std::ldexp(1.0, static_cast<int>(rng() % 48) - 4);  // 1/16 .. 2^43 rad
    const double a = unit(rng) * scale;
    ASSERT_TRUE(same_bits(wrap_two_pi(a), reference(a))) << a;
  }
  // Next to multiples of 2π, where a / 2π rounds to the neighbouring integer.
  for (std::int64_t n = -200000; n <= 200000; n += 7) {
    const double m = static_cast<double>(n) * kTwoPi;
    for (double a = std::nextafter(m, -1e300), k = 0; k < 5; a = std::nextafter(a, 1e300), ++k) {
      ASSERT_TRUE(same_bits(wrap_two_pi(a), reference(a))) << a;
    }
  }
  for (const double a : {0.0, -0.0, kTwoPi, -kTwoPi, 1e300, -1e300, std::numeric_limits<double>::denorm_min(),
                         std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_TRUE(same_bits(wrap_two_pi(a), reference(a))) << a;
  }
}
