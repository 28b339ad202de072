// Four-bar analysis against independent truth: loop closure, finite differences of the closed-form
// positions, the rocker at rest at the dead centres, and textbook Grashof classes.
#include "loom/motion/fourbar.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/angles.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/motion/errors.hpp"

using namespace loom::motion;

namespace {
const FourBar kThesis = default_beatup_geometry().bar;

double closure_residual(const FourBar& m, const FourBarPose& p) {
  const double x = m.crank * std::cos(p.theta2) + m.coupler * std::cos(p.theta3) - m.ground -
                   m.rocker * std::cos(p.theta4);
  const double y =
      m.crank * std::sin(p.theta2) + m.coupler * std::sin(p.theta3) - m.rocker * std::sin(p.theta4);
  return std::hypot(x, y);
}
}  // namespace

TEST(FourBar, GrashofClasses) {
  EXPECT_EQ(classify(kThesis), GrashofClass::kCrankRocker);
  EXPECT_EQ(classify({.ground = 1, .crank = 3, .coupler = 3.5, .rocker = 3.2}), GrashofClass::kDoubleCrank);
  EXPECT_EQ(classify({.ground = 3, .crank = 3.5, .coupler = 1, .rocker = 3.2}), GrashofClass::kDoubleRocker);
  EXPECT_EQ(classify({.ground = 3, .crank = 3.5, .coupler = 3.2, .rocker = 1}), GrashofClass::kRockerCrank);
  EXPECT_EQ(classify({.ground = 1, .crank = 2, .coupler = 3, .rocker = 5}), GrashofClass::kTripleRocker);
  EXPECT_EQ(classify({.ground = 2, .crank = 1, .coupler = 2, .rocker = 1}), GrashofClass::kChangePoint);
  EXPECT_THROW(classify({.ground = 1, .crank = -1, .coupler = 2, .rocker = 2}), MotionError);
}

TEST(FourBar, LoopClosesOnBothBranchesThroughATurn) {
  for (Branch br : {Branch::kPositive, Branch::kNegative}) {
    for (int i = 0; i < 3600; ++i) {
      const FourBarPose p = solve(kThesis, rad(i * 0.1), br);
      EXPECT_LE(closure_residual(kThesis, p), 1e-12 * kThesis.ground);
    }
  }
}

TEST(FourBar, CoefficientsMatchFiniteDifferences) {
  const double h = 1e-5;
  for (Branch br : {Branch::kPositive, Branch::kNegative}) {
    for (int i = 0; i < 360; i += 7) {
      const double t = rad(i);
      const FourBarPose p = solve(kThesis, t, br), pp = solve(kThesis, t + h, br),
                        pm = solve(kThesis, t - h, br);
      const double k4_fd = wrap_pi(pp.theta4 - pm.theta4) / (2 * h);
      const double k3_fd = wrap_pi(pp.theta3 - pm.theta3) / (2 * h);
      const double k4p_fd = (pp.k4 - pm.k4) / (2 * h);
      const double k3p_fd = (pp.k3 - pm.k3) / (2 * h);
      EXPECT_NEAR(p.k4, k4_fd, 1e-6 * std::max(1.0, std::abs(p.k4)));
      EXPECT_NEAR(p.k3, k3_fd, 1e-6 * std::max(1.0, std::abs(p.k3)));
      EXPECT_NEAR(p.k4p, k4p_fd, 1e-6 * std::max(1.0, std::abs(p.k4p)));
      EXPECT_NEAR(p.k3p, k3p_fd, 1e-6 * std::max(1.0, std::abs(p.k3p)));
    }
  }
}

TEST(FourBar, TimeDerivativesFollowTheChainRule) {
  const FourBarPose p = solve(kThesis, 1.0, Branch::kPositive);
  const AngularMotion m = rocker_motion(p, 15.5, 3.0);
  EXPECT_DOUBLE_EQ(m.velocity, p.k4 * 15.5);
  EXPECT_DOUBLE_EQ(m.acceleration, p.k4 * 3.0 + p.k4p * 15.5 * 15.5);
}

TEST(FourBar, DeadCentresHaveTheRockerAtRestAndMatchTheLawOfCosines) {
  for (Branch br : {Branch::kPositive, Branch::kNegative}) {
    const DeadCentres dc = dead_centres(kThesis, br);
    EXPECT_NEAR(solve(kThesis, dc.crank_extended, br).k4, 0.0, 1e-9);
    EXPECT_NEAR(solve(kThesis, dc.crank_folded, br).k4, 0.0, 1e-9);
    // Independent: |A0 B| = b ± a at the dead centres gives cos θ4 by the law of cosines in A0 B0 B.
    const auto cos4 = [&](double reach) {
      const double d = kThesis.ground, c = kThesis.rocker;
      return (reach * reach - d * d - c * c) / (2 * d * c);
    };
    EXPECT_NEAR(std::cos(dc.rocker_extended), cos4(kThesis.coupler + kThesis.crank), 1e-12);
    EXPECT_NEAR(std::cos(dc.rocker_folded), cos4(kThesis.coupler - kThesis.crank), 1e-12);
    EXPECT_NEAR(dc.swing, std::abs(std::acos(cos4(0.247)) - std::acos(cos4(0.131))), 1e-12);
    EXPECT_GT(dc.time_ratio, 0.0);
  }
}

TEST(FourBar, MinimumTransmissionAngleIsAtCrankZeroOrPi) {
  const DeadCentres dc = dead_centres(kThesis, Branch::kPositive);
  double worst = kPi;
  for (int i = 0; i < 36000; ++i) {
    const double mu = solve(kThesis, rad(i * 0.01), Branch::kPositive).transmission;
    worst = std::min(worst, std::min(mu, kPi - mu));
  }
  EXPECT_NEAR(dc.mu_min, worst, 1e-6);
}

TEST(FourBar, NotAssemblableIsATypedErrorNotNaN) {
  // Double-rocker: the crank cannot reach θ2 = π.
  const FourBar dr{.ground = 3, .crank = 3.5, .coupler = 1, .rocker = 3.2};
  try {
    (void)solve(dr, kPi, Branch::kPositive);
    FAIL() << "expected MotionError";
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotAssemblable);
  }
  EXPECT_THROW((void)dead_centres(dr, Branch::kPositive), MotionError);
}

TEST(FourBar, ChangePointAtTheFlatPoseIsFlaggedSingular) {
  // Parallelogram-like change point: at θ2 = 0 all links lie on the ground line.
  const FourBar cp{.ground = 2, .crank = 1, .coupler = 2, .rocker = 1};
  try {
    (void)solve(cp, 0.0, Branch::kPositive);
    FAIL() << "expected MotionError";
  } catch (const MotionError& e) {
    EXPECT_TRUE(e.code() == ErrorCode::kSingular || e.code() == ErrorCode::kNotAssemblable);
  }
  // Just off the flat pose it is finite.
  const FourBarPose p = solve(cp, 1e-3, Branch::kPositive);
  EXPECT_TRUE(std::isfinite(p.k4) && std::isfinite(p.k4p));
}
