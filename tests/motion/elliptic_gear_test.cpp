// Elliptic k-lobed gear of seed 004 against independent truth: numerical quadrature of eqn 5, the
// printed gear-ratio function (eqn 6), rolling without slip, the identical-mating-pinion property,
// finite differences of φ2, and the exact reduction to a circular gear at e = 0.
#include "loom/motion/elliptic_gear.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "finite_diff.hpp"
#include "loom/motion/angles.hpp"

namespace loom::motion {
namespace {

// Composite Simpson of 004 eqn 5's integrand from 0 to x: an independent route to φ2.
double phi2_by_quadrature(double e, int k, double x) {
  const int n = 20000;
  const double h = x / n;
  const auto f = [&](double p) { return (1 - e * e) / (1 + 2 * e * std::cos(k * p) + e * e); };
  double sum = f(0) + f(x);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * f(i * h);
  return sum * h / 3;
}

TEST(EllipticGear, ClosedFormMatchesQuadratureOfEquationFive) {
  for (int k : {1, 2, 3}) {
    for (double e : {0.05, 0.2, 0.33}) {
      const EllipticGearPair g(0.05, e, k);
      for (double x : {0.1, 0.7, 1.6, 2.5, 3.9, 6.0}) {
        EXPECT_NEAR(g.phase(x).phi2_rad, phi2_by_quadrature(e, k, x), 1e-11) << "k " << k << " e " << e;
      }
    }
  }
}

TEST(EllipticGear, RatioIsPrintedEquationSix) {
  const double e = 0.2;
  const EllipticGearPair g(0.05, e, 2);
  for (int i = 0; i < 100; ++i) {
    const double p = kTwoPi * i / 100.0;
    const double eq6 = (1 + 2 * e * std::cos(2 * p) + e * e) / (1 - e * e);
    EXPECT_NEAR(g.ratio(p), eq6, 1e-15);
    EXPECT_NEAR(g.phase(p).dphi2 * g.ratio(p), 1.0, 1e-15);  // i12 = dφ1/dφ2
  }
  // 004's e = 0.2: the crank runs between (1-e)/(1+e) = 2/3 and (1+e)/(1-e) = 3/2 of ω1.
  EXPECT_NEAR(g.phase(0.0).dphi2, 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(g.phase(kPi / 2).dphi2, 1.5, 1e-15);
  EXPECT_NEAR(g.max_speed_ratio(), 1.5, 1e-15);
}

TEST(EllipticGear, PinionsRollWithoutSlipAtCentreDistanceTwoA) {
  const double a = 0.05;
  for (int k : {1, 2, 4}) {
    const EllipticGearPair g(a, 0.25 / (k * k), k);
    const double p = g.semi_latus_rectum_m();
    for (int i = 0; i < 200; ++i) {
      const double x = kTwoPi * i / 200.0;
      const double r1 = g.driver_radius_m(x), r2 = g.driven_radius_m(x);
      const GearPhase ph = g.phase(x);
      EXPECT_NEAR(r1 + r2, 2 * a, 1e-16);
      EXPECT_NEAR(r1, r2 * ph.dphi2, 1e-16);  // equal arc lengths: r1 dφ1 = r2 dφ2
      // The driven pinion is the same curve turned by π/k: r2 = p/(1 - e cos kφ2).
      EXPECT_NEAR(r2, p / (1 - g.eccentricity() * std::cos(k * ph.phi2_rad)), 1e-15);
    }
  }
}

TEST(EllipticGear, DerivativesMatchFiniteDifferences) {
  for (int k : {1, 2, 3}) {
    for (double e : {0.1, 0.2, 0.5, 0.9}) {
      const EllipticGearPair g(0.05, e, k);
      const double h = 1e-3 / k;
      double s1 = 0, s2 = 0;
      for (int i = 0; i < 400; ++i) {
        s1 = std::max(s1, std::abs(g.phase(kTwoPi * i / 400).dphi2));
        s2 = std::max(s2, std::abs(g.phase(kTwoPi * i / 400).d2phi2));
      }
      for (int i = 0; i < 400; ++i) {
        const double x = kTwoPi * i / 400.0 + 0.01;
        const double fd1 = test::d1([&](double y) { return g.phase(y).phi2_rad; }, x, h);
        const double fd2 = test::d1([&](double y) { return g.phase(y).dphi2; }, x, h * (1 - e));
        EXPECT_TRUE(test::close_rel(g.phase(x).dphi2, fd1, s1, 1e-6)) << k << " " << e << " " << x;
        EXPECT_TRUE(test::close_rel(g.phase(x).d2phi2, fd2, s2, 1e-6)) << k << " " << e << " " << x;
      }
    }
  }
}

TEST(EllipticGear, CircularGearAtZeroEccentricityIsExact) {
  const EllipticGearPair g(0.05, 0.0, 2);
  for (int i = 0; i < 1000; ++i) {
    const double x = 0.0137 * i - 3.0;
    const GearPhase ph = g.phase(x);
    EXPECT_EQ(ph.phi2_rad, x);
    EXPECT_EQ(ph.dphi2, 1.0);
    EXPECT_EQ(ph.d2phi2, 0.0);
    EXPECT_EQ(g.ratio(x), 1.0);
    EXPECT_EQ(g.driver_radius_m(x), 0.05);
    EXPECT_EQ(g.driven_radius_m(x), 0.05);
  }
  EXPECT_FALSE(g.near_degenerate());
  EXPECT_FALSE(g.concave_pitch_curve());
}

TEST(EllipticGear, NoBranchJumpOverManyTurns) {
  const EllipticGearPair g(0.05, 0.6, 2);
  double prev = g.phase(0.0).phi2_rad;
  for (int i = 1; i <= 100 * 720; ++i) {
    const double x = kTwoPi * i / 720.0;
    const double now = g.phase(x).phi2_rad;
    EXPECT_GT(now, prev);                       // the driven pinion never reverses
    EXPECT_LT(now - prev, 4.0 * kTwoPi / 720);  // and never jumps: ≤ (1+e)/(1-e) times the step
    prev = now;
  }
  EXPECT_NEAR(g.phase(100 * kTwoPi).phi2_rad, 100 * kTwoPi, 1e-11);  // one driven turn per turn
  EXPECT_NEAR(g.phase(1.234 + kTwoPi).phi2_rad - g.phase(1.234).phi2_rad, kTwoPi, 1e-14);
}

// Curvature sign of r = p/(1 + e cos kφ): r² + 2r'² - r r'' (numerical derivatives, independent of
// the 1/(k² - 1) bound the library uses).
double min_convexity(double e, int k) {
  double m = 1e300;
  const auto r = [&](double t) { return 1.0 / (1 + e * std::cos(k * t)); };
  for (int i = 0; i < 4000; ++i) {
    const double t = kTwoPi * i / 4000;
    const double r0 = r(t), r1 = test::d1(r, t, 1e-3), r2 = test::d2(r, t, 1e-3);
    m = std::min(m, r0 * r0 + 2 * r1 * r1 - r0 * r2);
  }
  return m;
}

TEST(EllipticGear, ConcavePitchCurveFlagMatchesCurvature) {
  for (int k : {2, 3}) {
    const double bound = 1.0 / (k * k - 1.0);
    for (double e : {0.9 * bound, 0.999 * bound, 1.001 * bound, 1.2 * bound}) {
      const EllipticGearPair g(0.05, e, k);
      EXPECT_EQ(g.concave_pitch_curve(), min_convexity(e, k) < 0.0) << "k " << k << " e " << e;
    }
  }
  EXPECT_FALSE(EllipticGearPair(0.05, 0.95, 1).concave_pitch_curve());  // true ellipses stay convex
}

}  // namespace
}  // namespace loom::motion
