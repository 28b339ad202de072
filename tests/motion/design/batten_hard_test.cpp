// Hard cases of the geared batten: impossible linkages get typed errors, a loop-2 toggle inside the
// swing is singular, e -> 1 keeps ψ, ψ', ψ'' finite over whole turns, and the solution is scale-free.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/batten.hpp"
#include "loom/motion/errors.hpp"
#include "motion_error.hpp"
#include "perturb.hpp"

namespace loom::motion {
namespace {

std::optional<ErrorCode> code_of(const BattenDims& d) {
  return test::error_of([&] { const BattenLinkage l(d); });
}

TEST(BattenHard, BadDimensionsAreTypedErrors) {
  BattenDims d = batten_004_dims();
  d.l4_m = 0.0;
  EXPECT_EQ(code_of(d), ErrorCode::kInvalidInput);
  d = batten_004_dims();
  d.l8_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(code_of(d), ErrorCode::kInvalidInput);
  d = batten_004_dims();
  d.l1_m = 0.07;  // |O1O3| + L1 = 0.187 > L2 + L3 = 0.17
  EXPECT_EQ(code_of(d), ErrorCode::kNotCrank);
  d = batten_004_dims();
  d.l5_m = 0.05;  // batten too short to meet L4 anywhere near the rocker
  EXPECT_EQ(code_of(d), ErrorCode::kNotAssemblable);
  try {
    const BattenDrive drv(EllipticGearPair(0.05, 0.2, 2), BattenLinkage(batten_004_dims()),
                          std::numeric_limits<double>::infinity());
    ADD_FAILURE();
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("phi02"), std::string::npos);
  }
}

TEST(BattenHard, LoopOneChangePointIsSingular) {
  BattenDims d = batten_004_dims();
  d.l7_m = 0.0;
  d.l6_m = 0.13;  // |O1O3| = 0.13, + L1 = 0.17 = L2 + L3
  d.l8_m = 0.03;
  EXPECT_EQ(code_of(d), ErrorCode::kSingular);
}

TEST(BattenHard, LoopTwoToggleIsSingularAndBeyondItNotAssemblable) {
  // |BP| is largest at one end of the L3 swing; make L4 + L5 equal to it exactly.
  const BattenDims base = batten_004_dims();
  const BattenLinkage l(base);
  const Eigen::Vector2d o3(-base.l7_m, base.l6_m), p(base.l9_m, 2 * base.l6_m + base.l8_m);
  double bp_max = 0.0;
  for (double g3 : {l.rocker_limits().extended_rad, l.rocker_limits().folded_rad}) {
    bp_max = std::max(bp_max, (o3 + base.l3_m * Eigen::Vector2d(std::cos(g3), std::sin(g3)) - p).norm());
  }
  // ... and no interior γ3 reaches farther: the far side of the circle (O3P reversed) is outside the swing.
  for (const BattenSample& s : batten_sweep(BattenDrive(EllipticGearPair(0.05, 0.0, 2), l, 0.0), 3600, 1.0)) {
    const Eigen::Vector2d b =
        o3 + base.l3_m * Eigen::Vector2d(std::cos(s.pose.gamma3_rad), std::sin(s.pose.gamma3_rad));
    ASSERT_LE((b - p).norm(), bp_max + 1e-15);
  }
  BattenDims d = base;
  d.l5_m = bp_max - d.l4_m;
  EXPECT_EQ(code_of(d), ErrorCode::kSingular);
  d.l5_m = bp_max - d.l4_m - 1e-6;
  EXPECT_EQ(code_of(d), ErrorCode::kNotAssemblable);
  d.l5_m = bp_max - d.l4_m + 1e-9;  // just clear of the toggle: valid and finite everywhere
  const BattenLinkage near(d);
  for (const BattenSample& s :
       batten_sweep(BattenDrive(EllipticGearPair(0.05, 0.2, 2), near, 0.3), 3600, 1.0)) {
    ASSERT_TRUE(std::isfinite(s.psi_rad) && std::isfinite(s.psi_dot_rad_s) &&
                std::isfinite(s.psi_ddot_rad_s2));
  }
}

TEST(BattenHard, EccentricityNearOneStaysFinite) {
  const BattenLinkage l(batten_004_dims());
  for (double e : {0.9, 0.99, 0.999, 1.0 - 1e-9, std::nextafter(1.0, 0.0)}) {
    const BattenDrive d(EllipticGearPair(kBatten004GearA_m, e, 2), l, 1.0);
    EXPECT_EQ(d.gear().near_degenerate(), (1.0 + e) / (1.0 - e) > 100.0);
    for (const BattenSample& s : batten_sweep(d, 3600, 1.0)) {
      ASSERT_TRUE(std::isfinite(s.phi2_rad) && std::isfinite(s.psi_rad) && std::isfinite(s.psi_dot_rad_s) &&
                  std::isfinite(s.psi_ddot_rad_s2))
          << "e " << e << " phi1 " << s.phi1_rad;
      ASSERT_LE(l.residual(s.phi2_rad, s.pose).cwiseAbs().maxCoeff(), 1e-12 * l.largest_link_m());
    }
    // The lobe points, where the driven pinion spins fastest: (1+e)/(1-e) times ω1.
    for (double phi1 : {kPi / 2, 3 * kPi / 2}) {
      const BattenSample s = d.evaluate(phi1, 1.0);
      ASSERT_TRUE(std::isfinite(s.psi_dot_rad_s) && std::isfinite(s.psi_ddot_rad_s2)) << e;
    }
  }
}

TEST(BattenHard, ScaleFreeFromMicrometreToKilometre) {
  const BattenDims base = batten_004_dims();
  const BattenLinkage ref(base);
  for (double k : {1e-5, 1e4}) {
    BattenDims d = base;
    for (double* v : {&d.l1_m, &d.l2_m, &d.l3_m, &d.l4_m, &d.l5_m, &d.l6_m, &d.l7_m, &d.l8_m, &d.l9_m})
      *v *= k;
    const BattenLinkage l(d);
    for (int i = 0; i < 360; ++i) {
      const double crank = kTwoPi * i / 360.0;
      const BattenPose a = ref.solve(crank), b = l.solve(crank);
      EXPECT_NEAR(b.psi_rad, a.psi_rad, 1e-12);
      EXPECT_NEAR(b.gamma2_rad, a.gamma2_rad, 1e-12);
      EXPECT_LE(l.residual(crank, b).cwiseAbs().maxCoeff(), 1e-12 * l.largest_link_m());
      const NewtonResult n = l.solve_newton(crank, b);
      EXPECT_EQ(n.iterations, 0);  // tolerance is relative to the links, so scale does not matter
    }
  }
}

TEST(BattenHard, PerturbedDesignsAreFiniteOrRejected) {
  int accepted = 0, refused = 0;
  test::Perturbation draw(777u, 0.75, 1.25);
  const auto next = [&draw] { return draw.next(); };
  for (int trial = 0; trial < 200; ++trial) {
    BattenDims d = batten_004_dims();
    for (double* v : {&d.l1_m, &d.l2_m, &d.l3_m, &d.l4_m, &d.l5_m, &d.l6_m, &d.l7_m, &d.l8_m, &d.l9_m})
      *v *= next();
    try {
      const BattenLinkage l(d);
      ++accepted;
      const BattenDrive drv(EllipticGearPair(0.05, 0.3, 2), l, 0.7);
      for (const BattenSample& s : batten_sweep(drv, 720, 1.0)) {
        ASSERT_TRUE(std::isfinite(s.psi_rad) && std::isfinite(s.psi_dot_rad_s) &&
                    std::isfinite(s.psi_ddot_rad_s2))
            << "trial " << trial;
        ASSERT_TRUE(s.rates.dot.allFinite() && s.rates.ddot.allFinite());
        ASSERT_LE(l.residual(s.phi2_rad, s.pose).cwiseAbs().maxCoeff(), 1e-12 * l.largest_link_m());
        ASSERT_TRUE(l.branch_of(s.pose) == l.branch());
      }
    } catch (const MotionError&) {
      ++refused;
    }
  }
  EXPECT_GT(accepted, 20);
  EXPECT_GT(refused, 20);
}

}  // namespace
}  // namespace loom::motion
