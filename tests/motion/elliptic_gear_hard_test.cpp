// Hard cases of the elliptic gear: e >= 1 (and other impossible inputs) are typed errors naming the
// field; e -> 1 stays finite and monotone and is flagged as near-degenerate.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "loom/motion/angles.hpp"
#include "loom/motion/elliptic_gear.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {
namespace {

void expect_invalid(double a, double e, int k, const char* field) {
  try {
    const EllipticGearPair g(a, e, k);
    ADD_FAILURE() << "accepted a=" << a << " e=" << e << " k=" << k;
  } catch (const MotionError& err) {
    EXPECT_EQ(err.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(err.what()).find(field), std::string::npos) << err.what();
  }
}

TEST(EllipticGearHard, EccentricityOneOrMoreIsInvalid) {
  expect_invalid(0.05, 1.0, 2, "e = 1");
  expect_invalid(0.05, 1.5, 2, "e = 1.5");
  expect_invalid(0.05, -0.1, 2, "e = -0.1");
  expect_invalid(0.05, std::numeric_limits<double>::quiet_NaN(), 2, "e = nan");
  expect_invalid(0.0, 0.2, 2, "a = 0");
  expect_invalid(-0.05, 0.2, 2, "a = -0.05");
  expect_invalid(0.05, 0.2, 0, "k = 0");
}

TEST(EllipticGearHard, EccentricityNearOneIsFiniteMonotoneAndFlagged) {
  for (double e : {0.999, 1.0 - 1e-9, 1.0 - 1e-15, std::nextafter(1.0, 0.0)}) {
    const EllipticGearPair g(0.05, e, 2);
    EXPECT_TRUE(g.near_degenerate()) << e;
    EXPECT_TRUE(std::isfinite(g.max_speed_ratio()));
    double prev = -1e300;
    for (int i = 0; i <= 20000; ++i) {
      // Include the exact lobe points kφ1 = π, where the ratio denominator is smallest.
      const double x = kPi * i / 10000.0 - 0.5 * kPi;
      const GearPhase ph = g.phase(x);
      ASSERT_TRUE(std::isfinite(ph.phi2_rad) && std::isfinite(ph.dphi2) && std::isfinite(ph.d2phi2))
          << "e " << e << " x " << x;
      ASSERT_GT(ph.dphi2, 0.0);
      ASSERT_TRUE(std::isfinite(g.ratio(x)) && g.ratio(x) > 0.0);
      ASSERT_TRUE(std::isfinite(g.driver_radius_m(x)) && std::isfinite(g.driven_radius_m(x)));
      ASSERT_GE(ph.phi2_rad, prev) << "e " << e << " x " << x;
      prev = ph.phi2_rad;
    }
    // The limit staircase: over one turn the driven pinion still turns exactly once.
    EXPECT_NEAR(g.phase(kTwoPi + 0.3).phi2_rad - g.phase(0.3).phi2_rad, kTwoPi, 1e-12);
  }
  EXPECT_FALSE(EllipticGearPair(0.05, 0.2, 2).near_degenerate());
  // The threshold, from the closed form (1+e)/(1-e) > 100 <=> e > 99/101, on both sides of it.
  EXPECT_TRUE(EllipticGearPair(0.05, 0.99, 2).near_degenerate());  // (1.99/0.01) = 199: flagged
  EXPECT_NEAR(EllipticGearPair(0.05, 0.99, 2).max_speed_ratio(), 199.0, 199.0 * 1e-13);
  EXPECT_TRUE(EllipticGearPair(0.05, std::nextafter(99.0 / 101.0, 1.0), 2).near_degenerate());
  EXPECT_FALSE(EllipticGearPair(0.05, 0.98, 2).near_degenerate());  // 1.98/0.02 = 99: not flagged
}

TEST(EllipticGearHard, NearOneStillRollsWithoutSlip) {
  const double e = 1.0 - 1e-9;
  const EllipticGearPair g(0.05, e, 2);
  for (int i = 0; i < 1000; ++i) {
    const double x = kTwoPi * i / 1000.0;
    const double r1 = g.driver_radius_m(x), r2 = g.driven_radius_m(x);
    EXPECT_NEAR((r1 + r2) / 0.1, 1.0, 1e-12);
    EXPECT_NEAR(r1 / (r2 * g.phase(x).dphi2), 1.0, 1e-9);
  }
}

}  // namespace
}  // namespace loom::motion
