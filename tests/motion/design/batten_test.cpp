// Batten drive of seed 004 against independent truth: eqns (7) residuals, the documented frame and
// branch sides checked on explicit points, the batten's extremes against dead-centre geometry of
// either loop, finite differences of ψ in time, and Newton (the paper's route) against the closed form.
#include "loom/motion/design/batten.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "finite_diff.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {
namespace {

using Eigen::Vector2d;

Vector2d circle_point(const Vector2d& c0, double r0, const Vector2d& c1, double r1, int sign) {
  const double d = (c1 - c0).norm();
  const double a = (d * d + r0 * r0 - r1 * r1) / (2 * d);
  const double h = std::sqrt(r0 * r0 - a * a);
  const Vector2d ex = (c1 - c0) / d, ey(-ex.y(), ex.x());
  return c0 + a * ex + sign * h * ey;
}

double cross(const Vector2d& a, const Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

struct Points {
  Vector2d a, b, d, o3, p;
};

// The joints, rebuilt from a pose with the frame documented in batten.hpp.
Points points(const BattenDims& dm, double crank, const BattenPose& x) {
  Points q;
  q.a = {dm.l1_m * std::cos(crank), dm.l1_m * std::sin(crank)};
  q.b = q.a + dm.l2_m * Vector2d(std::sin(x.gamma2_rad), std::cos(x.gamma2_rad));
  q.o3 = {-dm.l7_m, dm.l6_m};
  q.p = {dm.l9_m, 2 * dm.l6_m + dm.l8_m};
  q.d = q.p + dm.l5_m * Vector2d(-std::sin(x.psi_rad), std::cos(x.psi_rad));
  return q;
}

TEST(Batten, ClosedFormClosesEquationsSevenOnItsBranch) {
  const BattenDims dm = batten_004_dims();
  for (BattenBranch br :
       {BattenBranch{LoopSide::kRight, LoopSide::kRight}, BattenBranch{LoopSide::kRight, LoopSide::kLeft}}) {
    const BattenLinkage l(dm, br);
    for (int i = 0; i < 3600; ++i) {
      const double crank = kTwoPi * i / 3600.0;
      const BattenPose x = l.solve(crank);
      ASSERT_LE(l.residual(crank, x).cwiseAbs().maxCoeff(), 1e-12 * l.largest_link_m());
      ASSERT_TRUE(l.branch_of(x) == br);
      // The sides named in the API, checked on the joints themselves.
      const Points q = points(dm, crank, x);
      EXPECT_NEAR((q.b - q.o3).norm(), dm.l3_m, 1e-15);
      EXPECT_NEAR((q.b - q.d).norm(), dm.l4_m, 1e-15);
      EXPECT_NEAR(std::atan2(q.b.y() - q.d.y(), q.b.x() - q.d.x()), x.gamma4_rad, 1e-12);
      EXPECT_EQ(cross(q.o3 - q.a, q.b - q.a) > 0, br.loop1 == LoopSide::kLeft);
      EXPECT_EQ(cross(q.p - q.b, q.d - q.b) > 0, br.loop2 == LoopSide::kLeft);
    }
  }
}

TEST(Batten, LeftLoopOneCannotReachTheBatten) {
  try {
    const BattenLinkage l(batten_004_dims(), BattenBranch{LoopSide::kLeft, LoopSide::kRight});
    FAIL() << "expected kNotAssemblable";
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotAssemblable);
  }
}

// Refine a zero of ψ'(φ1) by bisection between two sweep samples.
double refine_extreme(const BattenDrive& d, double lo, double hi) {
  double flo = d.evaluate(lo, 1.0).psi_dot_rad_s;
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double fm = d.evaluate(mid, 1.0).psi_dot_rad_s;
    if ((fm > 0) == (flo > 0)) {
      lo = mid;
      flo = fm;
    } else {
      hi = mid;
    }
  }
  return d.evaluate(0.5 * (lo + hi), 1.0).psi_rad;
}

// ψ stands still either when the rocker L3 does (loop 1 at a dead centre) or when O3, B, D line up
// (loop 2 at its own dead centre). Both are plain triangles, independent of eqns (7) and Newton.
std::vector<double> dead_centre_psis(const BattenLinkage& l) {
  const BattenDims& dm = l.dims();
  const Vector2d o1(0, 0), o3(-dm.l7_m, dm.l6_m), p(dm.l9_m, 2 * dm.l6_m + dm.l8_m);
  const auto psi_of = [&](const Vector2d& d) {
    return wrap_two_pi(std::atan2(-(d.x() - p.x()), d.y() - p.y()));
  };
  std::vector<double> out;
  for (int s : {-1, 1}) {
    // Loop 2 stretched: |O3 D| = L3 + L4.
    out.push_back(psi_of(circle_point(o3, dm.l3_m + dm.l4_m, p, dm.l5_m, s)));
    for (double r : {dm.l2_m + dm.l1_m, dm.l2_m - dm.l1_m}) {
      // Loop 1 at a dead centre: |O1 B| = L2 ± L1, then loop 2 closed from that B.
      for (int s1 : {-1, 1}) {
        const Vector2d b = circle_point(o1, r, o3, dm.l3_m, s1);
        out.push_back(psi_of(circle_point(b, dm.l4_m, p, dm.l5_m, s)));
      }
    }
  }
  return out;
}

TEST(Batten, TwoSwingsPerTurnWithExtremesAtDeadCentres) {
  const BattenLinkage l(batten_004_dims());
  for (double e : {0.0, 0.2}) {
    const BattenDrive d(EllipticGearPair(kBatten004GearA_m, e, 2), l, 1.0);
    const auto sw = batten_sweep(d, 3600, 1.0);
    std::vector<double> maxima, minima;
    for (std::size_t i = 0; i < sw.size(); ++i) {
      const std::size_t j = (i + 1) % sw.size();
      const double a = sw[i].psi_dot_rad_s, b = sw[j].psi_dot_rad_s;
      if ((a > 0) != (b > 0)) {
        const double hi = j == 0 ? kTwoPi : sw[j].phi1_rad;
        (a > 0 ? maxima : minima).push_back(refine_extreme(d, sw[i].phi1_rad, hi));
      }
    }
    ASSERT_EQ(maxima.size(), 2u) << "e " << e;  // 004: the batten swings twice per crank turn
    ASSERT_EQ(minima.size(), 2u);
    EXPECT_NEAR(maxima[0], maxima[1], 1e-12);  // both beats reach the same front position
    // The library's own turning-point finder agrees with this one.
    const std::vector<BattenExtreme> ex = batten_extremes(d, 360, 1.0);
    ASSERT_EQ(ex.size(), 4u);
    std::vector<double> lib_max, lib_min;
    for (const BattenExtreme& x : ex) (x.maximum ? lib_max : lib_min).push_back(x.psi_rad);
    ASSERT_EQ(lib_max.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
      EXPECT_NEAR(lib_max[k], maxima[k], 1e-12);
      EXPECT_NEAR(lib_min[k], minima[k], 1e-12);
    }
    const std::vector<double> truth = dead_centre_psis(l);
    for (double v : {maxima[0], maxima[1], minima[0], minima[1]}) {
      double best = 1e9;
      for (double t : truth) best = std::min(best, std::abs(wrap_pi(v - t)));
      EXPECT_LT(best, 1e-10) << "extreme psi " << v << " matches no dead centre";
    }
  }
}

TEST(Batten, RatesMatchFiniteDifferencesOfPositions) {
  const BattenLinkage l(batten_004_dims());
  struct Case {
    double e, phi02, omega1, alpha1;
  };
  for (const Case c : {Case{0.0, 0.0, 1.0, 0.0}, Case{0.2, 1.0, 1.0, 0.0}, Case{0.5, 2.5, 7.0, 3.0}}) {
    const BattenDrive d(EllipticGearPair(kBatten004GearA_m, c.e, 2), l, c.phi02);
    const auto phi1_at = [&](double t) { return c.omega1 * t + 0.5 * c.alpha1 * t * t; };
    const auto at = [&](double t) { return d.evaluate(phi1_at(t), c.omega1 + c.alpha1 * t, c.alpha1); };
    const double period = kTwoPi / c.omega1;
    constexpr int kPoints = 720;
    Eigen::Vector4d vmax = Eigen::Vector4d::Zero(), amax = Eigen::Vector4d::Zero();
    for (int i = 0; i < kPoints; ++i) {
      const BattenSample s = at(period * i / kPoints);
      vmax = vmax.cwiseMax(s.rates.dot.cwiseAbs());
      amax = amax.cwiseMax(s.rates.ddot.cwiseAbs());
    }
    const double h = 1e-3 / c.omega1;
    for (int i = 0; i < kPoints; ++i) {
      const double t0 = period * i / kPoints;
      const BattenSample s0 = at(t0);
      for (int k = 0; k < 4; ++k) {
        const double p0 = s0.pose.vec()(k);
        const auto pos = [&](double t) { return p0 + wrap_pi(at(t).pose.vec()(k) - p0); };
        const double v = test::d1(pos, t0, h), a = test::d2(pos, t0, h);
        EXPECT_TRUE(test::close_rel(s0.rates.dot(k), v, vmax(k), 1e-6))
            << "e " << c.e << " unknown " << k << " t " << t0 << ": " << s0.rates.dot(k) << " vs " << v;
        EXPECT_TRUE(test::close_rel(s0.rates.ddot(k), a, amax(k), 1e-6))
            << "e " << c.e << " unknown " << k << " t " << t0 << ": " << s0.rates.ddot(k) << " vs " << a;
      }
      EXPECT_EQ(s0.psi_dot_rad_s, s0.rates.dot(3));
      EXPECT_EQ(s0.psi_ddot_rad_s2, s0.rates.ddot(3));
    }
  }
}

TEST(Batten, CircularGearLeavesTheCrankUniform) {
  // e = 0: φ2 = φ02 + φ1 exactly, so the drive is the bare linkage at constant crank speed.
  const BattenLinkage l(batten_004_dims());
  const BattenDrive d(EllipticGearPair(kBatten004GearA_m, 0.0, 2), l, 1.0);
  for (int i = 0; i < 360; ++i) {
    const double phi1 = kTwoPi * i / 360.0;
    const BattenSample s = d.evaluate(phi1, 2.0);
    EXPECT_EQ(s.phi2_rad, 1.0 + phi1);
    const BattenRates r = l.rates(1.0 + phi1, l.solve(1.0 + phi1), 2.0, 0.0);
    EXPECT_EQ(s.psi_dot_rad_s, r.dot(3));
    EXPECT_EQ(s.psi_ddot_rad_s2, r.ddot(3));
  }
}

TEST(Batten, NewtonFromARoughGuessReachesTheClosedForm) {
  const BattenLinkage l(batten_004_dims());
  for (int i = 0; i < 72; ++i) {
    const double crank = kTwoPi * i / 72.0;
    const BattenPose exact = l.solve(crank);
    BattenPose guess = exact;
    guess.gamma2_rad += 0.2;
    guess.gamma3_rad -= 0.15;
    guess.gamma4_rad += 0.1;
    guess.psi_rad -= 0.1;
    const NewtonResult n = l.solve_newton(crank, guess);
    EXPECT_LE(n.iterations, 8);
    EXPECT_LE(n.residual_m, 1e-13 * l.largest_link_m());
    EXPECT_NEAR(wrap_pi(n.pose.gamma2_rad - exact.gamma2_rad), 0.0, 1e-12);
    EXPECT_NEAR(wrap_pi(n.pose.gamma3_rad - exact.gamma3_rad), 0.0, 1e-12);
    EXPECT_NEAR(wrap_pi(n.pose.gamma4_rad - exact.gamma4_rad), 0.0, 1e-12);
    EXPECT_NEAR(wrap_pi(n.pose.psi_rad - exact.psi_rad), 0.0, 1e-12);
  }
}

TEST(Batten, NewtonSweepEqualsClosedFormSweep) {
  const BattenLinkage l(batten_004_dims());
  const BattenDrive d(EllipticGearPair(kBatten004GearA_m, 0.2, 2), l, 1.0);
  const auto cf = batten_sweep(d, 3600, 1.0, BattenSolver::kClosedForm);
  const auto nw = batten_sweep(d, 3600, 1.0, BattenSolver::kNewton);
  ASSERT_EQ(cf.size(), nw.size());
  for (std::size_t i = 0; i < cf.size(); ++i) {
    EXPECT_NEAR(nw[i].psi_rad, cf[i].psi_rad, 1e-11);
    EXPECT_NEAR(nw[i].psi_ddot_rad_s2, cf[i].psi_ddot_rad_s2, 1e-9);
  }
}

TEST(Batten, NewtonLandingOnTheMirrorAssemblyIsCaught) {
  const BattenDims dm = batten_004_dims();
  const BattenLinkage want(dm);  // (right, right)
  const BattenLinkage mirror(dm, BattenBranch{LoopSide::kRight, LoopSide::kLeft});
  for (double crank : {0.0, 1.0, 2.0, 4.0}) {
    BattenPose guess = mirror.solve(crank);
    guess.psi_rad += 0.05;  // near the other assembly: Newton converges there, happily
    guess.gamma4_rad -= 0.05;
    try {
      (void)want.solve_newton(crank, guess);
      FAIL() << "expected kWrongBranch at crank " << crank;
    } catch (const MotionError& e) {
      EXPECT_EQ(e.code(), ErrorCode::kWrongBranch) << e.what();
    }
    // The same guess is right for the mirror linkage.
    EXPECT_NO_THROW((void)mirror.solve_newton(crank, guess));
  }
}

TEST(Batten, NewtonReportsBudgetSingularityAndBadOptions) {
  const BattenLinkage l(batten_004_dims());
  BattenPose far = l.solve(0.5);
  far.gamma2_rad += 0.4;
  try {
    (void)l.solve_newton(0.5, far, NewtonOptions{1e-13, 1});
    FAIL();
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNoConvergence);
  }
  // γ2 + γ3 = π/2 puts loop 1's Jacobian block at exactly zero determinant.
  BattenPose sing = l.solve(0.5);
  sing.gamma2_rad = kPi / 2 - sing.gamma3_rad;
  try {
    (void)l.solve_newton(0.5, sing);
    FAIL();
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kSingular);
  }
  for (NewtonOptions bad : {NewtonOptions{1e-17, 50}, NewtonOptions{1e-12, 0}}) {
    try {
      (void)l.solve_newton(0.5, l.solve(0.5), bad);
      FAIL();
    } catch (const MotionError& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    }
  }
}

TEST(Batten, SweepColumnsAreContinuous) {
  const BattenLinkage l(batten_004_dims());
  const BattenDrive d(EllipticGearPair(kBatten004GearA_m, 0.2, 2), l, 1.0);
  const auto sw = batten_sweep(d, 3600, 1.0);
  for (std::size_t i = 1; i < sw.size(); ++i) {
    EXPECT_GT(sw[i].phi2_rad, sw[i - 1].phi2_rad);
    EXPECT_LT(std::abs(sw[i].psi_rad - sw[i - 1].psi_rad), rad(0.2));
    EXPECT_LT(std::abs(sw[i].pose.gamma2_rad - sw[i - 1].pose.gamma2_rad), rad(1.0));
  }
  EXPECT_NEAR(sw.front().phi2_rad, 1.0, 1e-15);
}

}  // namespace
}  // namespace loom::motion
