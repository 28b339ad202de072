// Four-bar hard cases (issue 6, label numeric): toggles where the loop's discriminant rounds below
// zero, the change point and its neighbourhood, Newton near a toggle, link ratios from 1e-6 to 1e6,
// and a property sweep: for valid input every function returns finite numbers or a typed error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/slider_crank.hpp"
#include "motion_error.hpp"

namespace loom::motion {
namespace {

using test::error_of;

double largest(const FourBar& m) {
  return std::max({m.ground, m.crank, m.coupler, m.rocker});
}

double closure(const FourBar& m, double t2, double t3, double t4) {
  return std::hypot(m.crank * std::cos(t2) + m.coupler * std::cos(t3) - m.ground - m.rocker * std::cos(t4),
                    m.crank * std::sin(t2) + m.coupler * std::sin(t3) - m.rocker * std::sin(t4));
}

bool finite(const FourBarPose& p) {
  for (double v : {p.theta2, p.theta3, p.theta4, p.k3, p.k4, p.k3p, p.k4p, p.transmission}) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// Triple rocker (1, 2, 3, 5): the crank stops where |A B0| = c − b = 2, i.e. cos θ2 = 1/4; there the
// coupler lies along the rocker (toggle), B on the ray B0 → A.
const FourBar kTriple{.ground = 1, .crank = 2, .coupler = 3, .rocker = 5};
const double kTripleLimit = std::acos(0.25);

TEST(FourBarHard, ToggleLimitWithinRoundingIsClampedAndFlaggedNotNaN) {
  double t = kTripleLimit;
  for (int i = 0; i < 64; ++i) t = std::nextafter(t, 0.0);  // start 64 ulps outside the travel
  int flagged = 0, regular = 0;
  for (int i = 0; i < 128; ++i, t = std::nextafter(t, 4.0)) {
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      const FourBarPosition p = solve_position(kTriple, t, br);  // no throw: the miss is rounding
      ASSERT_TRUE(std::isfinite(p.theta3) && std::isfinite(p.theta4) && std::isfinite(p.transmission)) << i;
      EXPECT_LE(closure(kTriple, t, p.theta3, p.theta4), 1e-12 * largest(kTriple));
      // Independent truth: at the limit B lies on the ray B0 → A and the coupler points along it.
      const double ray = std::atan2(2 * std::sin(t), 2 * std::cos(t) - 1);
      EXPECT_NEAR(wrap_pi(p.theta4 - ray), 0.0, 1e-7) << i;
      EXPECT_NEAR(p.transmission, 0.0, 1e-7) << i;
      if (p.at_toggle) {
        ++flagged;
        EXPECT_EQ(error_of([&] { (void)solve(kTriple, t, br); }), ErrorCode::kSingular);
      } else {
        ++regular;
        const FourBarPose q = solve(kTriple, t, br);  // huge but finite rates ~ 1/sqrt(distance)
        EXPECT_TRUE(finite(q)) << i;
      }
    }
  }
  EXPECT_GT(flagged, 0);  // the discriminant did round to zero or below on this side ...
  EXPECT_GT(regular, 0);  // ... and inside the travel the pose is regular again
}

TEST(FourBarHard, ToggleLimitBeyondRoundingIsNotAssemblable) {
  for (double beyond : {1e-9, 1e-6, 1e-3}) {
    EXPECT_EQ(error_of([&] { (void)solve_position(kTriple, kTripleLimit - beyond, Branch::kPositive); }),
              ErrorCode::kNotAssemblable)
        << beyond;
    // Inside by the same amount: two branches, mirror images about the ray B0 → A.
    const FourBarPose p = solve(kTriple, kTripleLimit + beyond, Branch::kPositive);
    const FourBarPose n = solve(kTriple, kTripleLimit + beyond, Branch::kNegative);
    const double ray =
        std::atan2(2 * std::sin(kTripleLimit + beyond), 2 * std::cos(kTripleLimit + beyond) - 1);
    EXPECT_NEAR(wrap_pi(p.theta4 - ray), -wrap_pi(n.theta4 - ray), 1e-12);
    EXPECT_GT(wrap_pi(p.theta4 - ray), 0.0);
    EXPECT_TRUE(finite(p) && finite(n));
  }
}

// Parallelogram change point a = c = 1, b = d = 2: flat at θ2 = 0 and π where its two branches meet.
// For θ2 in (0, π) the negative branch is the parallelogram itself: θ4 = θ2, θ3 = 0, k4 = 1, k3 = 0.
const FourBar kParallelogram{.ground = 2, .crank = 1, .coupler = 2, .rocker = 1};

TEST(FourBarHard, ChangePointFlatPoseIsFlaggedAndSingular) {
  for (double t : {0.0, kPi}) {
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      const FourBarPosition p = solve_position(kParallelogram, t, br);
      EXPECT_TRUE(p.at_toggle) << t;
      EXPECT_LE(closure(kParallelogram, t, p.theta3, p.theta4), 1e-15);
      EXPECT_EQ(error_of([&] { (void)solve(kParallelogram, t, br); }), ErrorCode::kSingular);
    }
  }
  EXPECT_EQ(classify(kParallelogram), GrashofClass::kChangePoint);
}

TEST(FourBarHard, BesideTheChangePointBothBranchesKeepFullAccuracy) {
  for (double eps : {1e-2, 1e-4, 1e-6, 1e-9, 1e-12}) {
    const FourBarPose par = solve(kParallelogram, eps, Branch::kNegative);
    EXPECT_NEAR(par.theta4, eps, 1e-15 * eps + 1e-300);  // the Heron factors carry no cancellation
    EXPECT_NEAR(par.theta3, 0.0, 1e-15);
    EXPECT_NEAR(par.k4, 1.0, 1e-12);
    EXPECT_NEAR(par.k3, 0.0, 1e-12);
    EXPECT_NEAR(par.k4p, 0.0, 1e-9);
    // The crossed (antiparallelogram) branch: closes, is finite, and meets the other as ε → 0.
    const FourBarPose anti = solve(kParallelogram, eps, Branch::kPositive);
    EXPECT_TRUE(finite(anti));
    EXPECT_LE(closure(kParallelogram, eps, anti.theta3, anti.theta4), 1e-15);
    EXPECT_LT(std::abs(anti.theta4 - par.theta4), 5 * eps);
  }
}

TEST(FourBarHard, NearChangePointCrankRockerStaysFiniteAndAccurate) {
  // d = 1, a = 0.4, b = 1.2, c = 0.6 + δ: Grashof by δ, nearly folded at θ2 = 0 where μ_min ~ √δ.
  for (double delta : {1e-3, 1e-6, 1e-9, 1e-11}) {
    const FourBar m{.ground = 1.0, .crank = 0.4, .coupler = 1.2, .rocker = 0.6 + delta};
    ASSERT_EQ(classify(m), GrashofClass::kCrankRocker) << delta;
    // μ_min from Heron's area in long double on the very same (double) lengths: sin μ = 2·Area/(b c)
    // with the triangle (d − a, b, c). A one-ulp change of any length moves the triangle's defect
    // (~δ) by ~1e-16, so μ is only determined to a relative ~1e-16/δ.
    const long double b = m.coupler, c = m.rocker, f = static_cast<long double>(m.ground) - m.crank;
    const long double area4 = std::sqrt((f + b + c) * (-f + b + c) * (f - b + c) * (f + b - c));
    const double mu_ref = static_cast<double>(std::asin(area4 / (2.0L * b * c)));
    EXPECT_NEAR(transmission_range(m).mu_min / mu_ref, 1.0, 1e-15 / delta + 1e-12) << delta;
    const std::vector<FourBarPose> sw = fourbar_sweep(m, Branch::kPositive, 3600);
    for (const FourBarPose& p : sw) {
      ASSERT_TRUE(finite(p)) << delta;
      EXPECT_LE(closure(m, p.theta2, p.theta3, p.theta4), 1e-12 * largest(m));
    }
    const DeadCentres dc = dead_centres(m, Branch::kPositive);
    EXPECT_TRUE(std::isfinite(dc.swing) && std::isfinite(dc.time_ratio) && dc.mu_min > 0.0) << delta;
  }
}

TEST(FourBarHard, NewtonNearToggleConvergesToTheAskedBranchOrSaysWhyNot) {
  // μ ~ 4e-5 rad at θ2 = 0: the Jacobian b·c·sin μ is tiny and the two branches almost touch.
  const FourBar m{.ground = 1.0, .crank = 0.4, .coupler = 1.2, .rocker = 0.6 + 1e-9};
  int converged = 0, refused = 0;
  for (Branch br : {Branch::kPositive, Branch::kNegative}) {
    const FourBarPose cf = solve(m, 0.0, br);
    for (double off : {-0.05, -1e-3, 1e-4, 1e-3, 0.05}) {
      try {
        const FourBarNewtonResult n = solve_newton(m, 0.0, br, cf.theta3 + off, cf.theta4 - off);
        EXPECT_EQ(branch_of(n.pose.theta3, n.pose.theta4), br);
        // Ill-conditioned: the angle is determined only to ~ residual / (b c sin μ).
        EXPECT_NEAR(wrap_pi(n.pose.theta4 - cf.theta4), 0.0, 1e-7);
        ++converged;
      } catch (const MotionError& e) {
        EXPECT_TRUE(e.code() == ErrorCode::kWrongBranch || e.code() == ErrorCode::kSingular ||
                    e.code() == ErrorCode::kNoConvergence)
            << e.what();
        ++refused;
      }
    }
  }
  EXPECT_GT(converged, 0);
  EXPECT_EQ(converged + refused, 10);
}

// Crank-rockers and drag links whose links span six decades.
struct Extreme {
  const char* what;
  FourBar m;
};
const Extreme kExtremes[] = {
    {"tiny crank", {.ground = 1.0, .crank = 1e-6, .coupler = 1.0, .rocker = 0.8}},
    {"long coupler and rocker", {.ground = 1.0, .crank = 0.1, .coupler = 1e6, .rocker = 1e6 + 0.5}},
    {"long ground and coupler", {.ground = 1e6, .crank = 1.0, .coupler = 1e6 - 0.3, .rocker = 2.0}},
    {"tiny ground (drag link)", {.ground = 1e-6, .crank = 1.0, .coupler = 1.2, .rocker = 1.1}},
};

TEST(FourBarHard, TinyAndHugeLinkRatiosAtEveryScale) {
  for (const Extreme& x : kExtremes) {
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      const std::vector<FourBarPose> unit = fourbar_sweep(x.m, br, 720);
      for (double scale : {std::ldexp(1.0, -20), std::ldexp(1.0, 20)}) {  // ~1e-6, ~1e6, exact
        const FourBar s{x.m.ground * scale, x.m.crank * scale, x.m.coupler * scale, x.m.rocker * scale};
        const std::vector<FourBarPose> sw = fourbar_sweep(s, br, 720);
        for (std::size_t i = 0; i < sw.size(); ++i) {
          const FourBarPose& p = sw[i];
          ASSERT_TRUE(finite(p)) << x.what;
          EXPECT_LE(closure(s, p.theta2, p.theta3, p.theta4), 1e-12 * largest(s)) << x.what;
          // Angles and coefficients are dimensionless: a change of unit changes nothing.
          EXPECT_NEAR(p.theta4, unit[i].theta4, 1e-12) << x.what;
          EXPECT_NEAR(p.k4, unit[i].k4, 1e-9 * (1 + std::abs(unit[i].k4))) << x.what;
          EXPECT_NEAR(p.k4p, unit[i].k4p, 1e-9 * (1 + std::abs(unit[i].k4p))) << x.what;
        }
      }
      // Velocity closure: crank pin speed + coupler's turn = rocker pin speed, to rounding — which
      // is amplified by 1/sin μ, the conditioning of the coefficients' 2×2 system.
      for (const FourBarPose& p : unit) {
        const FourBar& m = x.m;
        const double vx = -m.crank * std::sin(p.theta2) - m.coupler * p.k3 * std::sin(p.theta3) +
                          m.rocker * p.k4 * std::sin(p.theta4);
        const double vy = m.crank * std::cos(p.theta2) + m.coupler * p.k3 * std::cos(p.theta3) -
                          m.rocker * p.k4 * std::cos(p.theta4);
        const double size = m.crank + m.coupler * std::abs(p.k3) + m.rocker * std::abs(p.k4);
        EXPECT_LE(std::hypot(vx, vy), 1e-15 * size / std::abs(std::sin(p.transmission))) << x.what;
      }
      const TransmissionRange r = transmission_range(x.m);
      EXPECT_TRUE(std::isfinite(r.mu_min) && std::isfinite(r.mu_max) && r.mu_min <= r.mu_max) << x.what;
      if (classify(x.m) == GrashofClass::kCrankRocker) {
        const DeadCentres dc = dead_centres(x.m, br);
        EXPECT_TRUE(std::isfinite(dc.swing) && dc.swing > 0.0 && std::isfinite(dc.time_ratio)) << x.what;
        EXPECT_NEAR(solve(x.m, dc.crank_extended, br).k4, 0.0, 1e-9) << x.what;
      }
    }
  }
}

TEST(FourBarHard, NoNaNOrInfForAnyValidInput) {
  // Link lengths log-uniform over 1e-6…1e6 and any crank angle: every call returns finite numbers
  // or throws a typed MotionError. Every other linkage is built to close at its crank angle (the
  // rocker is the distance from B0 to a random point on the coupler circle), since random lengths
  // mostly cannot be assembled.
  std::mt19937_64 gen(6);
  std::uniform_real_distribution<double> decade(-6.0, 6.0), angle(-10.0, 10.0);
  int evaluated = 0, refused = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    FourBar m{std::pow(10.0, decade(gen)), std::pow(10.0, decade(gen)), std::pow(10.0, decade(gen)),
              std::pow(10.0, decade(gen))};
    const double t = angle(gen);
    if (trial % 2 == 1) {
      const double phi = angle(gen);
      m.rocker = std::hypot(m.crank * std::cos(t) + m.coupler * std::cos(phi) - m.ground,
                            m.crank * std::sin(t) + m.coupler * std::sin(phi));
      if (!(m.rocker > 0.0)) continue;
    }
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      try {
        const FourBarPosition q = solve_position(m, t, br);
        ASSERT_TRUE(std::isfinite(q.theta3) && std::isfinite(q.theta4) && std::isfinite(q.transmission));
        const FourBarPose p = solve(m, t, br);
        ASSERT_TRUE(finite(p));
        const PointMotion pm = point_motion(
            point_coefficients(m, p, FourBarLink::kCoupler, {0.5 * m.coupler, 0.1 * m.coupler}), 2.0, 1.0);
        ASSERT_TRUE(pm.position.allFinite() && pm.velocity.allFinite() && pm.acceleration.allFinite());
        const FourBarNewtonResult n = solve_newton(m, t, br, p.theta3, p.theta4);
        ASSERT_TRUE(finite(n.pose));
        ++evaluated;
      } catch (const MotionError&) {
        ++refused;
      }
    }
    try {
      const DeadCentres dc = dead_centres(m, Branch::kPositive);
      ASSERT_TRUE(std::isfinite(dc.swing) && std::isfinite(dc.crank_rotation) &&
                  std::isfinite(dc.time_ratio) && std::isfinite(dc.mu_min));
      const TransmissionRange r = transmission_range(m);
      ASSERT_TRUE(std::isfinite(r.mu_min) && std::isfinite(r.mu_max));
    } catch (const MotionError&) {
    }
  }
  EXPECT_GT(evaluated, 10000);
  EXPECT_GT(refused, 1000);
}

TEST(SliderCrankHard, NoNaNOrInfForAnyValidInput) {
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> decade(-6.0, 6.0), unit(-1.0, 1.0), angle(-10.0, 10.0);
  int evaluated = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double a = std::pow(10.0, decade(gen));
    const double b = std::pow(10.0, decade(gen));
    const SliderCrank m{a, b, unit(gen) * b};
    try {
      validate_slider_crank(m);
    } catch (const MotionError&) {
      continue;
    }
    const double t = angle(gen);
    const SliderState s = slider_state(m, t, 3.0, -1.0);
    for (double v : {s.x, s.x_dot, s.x_ddot, s.coupler_angle_rad, s.transmission_rad, s.coupler_rate_rad_s,
                     s.coupler_accel_rad_s2}) {
      ASSERT_TRUE(std::isfinite(v)) << a << " " << b << " " << m.offset;
    }
    const PointCoefficients pc = slider_coupler_point(m, t, {0.5 * b, 0.2 * b});
    ASSERT_TRUE(pc.position.allFinite() && pc.d1.allFinite() && pc.d2.allFinite());
    const SliderDeadCentres dc = slider_dead_centres(m);
    for (double v :
         {dc.stroke, dc.time_ratio, dc.mu_min_rad, dc.phi_extend_to_fold_rad, dc.x_extended, dc.x_folded}) {
      ASSERT_TRUE(std::isfinite(v));
    }
    ++evaluated;
  }
  EXPECT_GT(evaluated, 1000);
}

// Issue 13: a linkage is the same at every scale a double holds. Squares of 1e150-long links overflow
// and of 1e-150-long links underflow unless the solver works in units of the largest link; before it
// did, a valid 1e80 linkage came out as a toggle.
TEST(FourBarHard, ScaleFreeFromOneEMinus150ToOneE150) {
  const FourBar unit_bar{0.213, 0.058, 0.189, 0.232};
  const TransmissionRange r1 = transmission_range(unit_bar);
  const DeadCentres dc1 = dead_centres(unit_bar, Branch::kPositive);
  for (double k : {1e-150, 1e-80, 1e80, 1e150, 1e300}) {
    const FourBar m{unit_bar.ground * k, unit_bar.crank * k, unit_bar.coupler * k, unit_bar.rocker * k};
    EXPECT_EQ(classify(m), GrashofClass::kCrankRocker) << k;
    for (int i = 0; i < 72; ++i) {
      const double t2 = kTwoPi * i / 72.0;
      const FourBarPosition p = solve_position(m, t2, Branch::kPositive);
      const FourBarPosition q = solve_position(unit_bar, t2, Branch::kPositive);
      EXPECT_FALSE(p.at_toggle) << k << " " << i;
      EXPECT_NEAR(p.theta3, q.theta3, 1e-13) << k << " " << i;
      EXPECT_NEAR(p.theta4, q.theta4, 1e-13) << k << " " << i;
      const FourBarPose a = solve(m, t2, Branch::kPositive), b = solve(unit_bar, t2, Branch::kPositive);
      EXPECT_NEAR(a.k4, b.k4, 1e-12) << k;
      EXPECT_NEAR(a.k4p, b.k4p, 1e-12) << k;
    }
    const TransmissionRange r = transmission_range(m);
    EXPECT_NEAR(r.mu_min, r1.mu_min, 1e-14) << k;
    EXPECT_NEAR(r.mu_max, r1.mu_max, 1e-14) << k;
    EXPECT_FALSE(r.near_toggle) << k;
    const DeadCentres dc = dead_centres(m, Branch::kPositive);
    EXPECT_NEAR(dc.crank_rotation, dc1.crank_rotation, 1e-13) << k;
    EXPECT_NEAR(dc.swing, dc1.swing, 1e-13) << k;
  }
}

// Issue 13: a linkage that turns but whose transmission angle passes within 1e-3 rad of a toggle is
// flagged with the value (here μ_min ≈ 1.4e-4°: rates amplified by ~4e5 there).
TEST(FourBarHard, NearToggleIsFlaggedWithItsValue) {
  const FourBar m{1.0, 0.249999999999, 0.25, 1.0};
  ASSERT_EQ(classify(m), GrashofClass::kCrankRocker);
  const TransmissionRange r = transmission_range(m);
  EXPECT_TRUE(r.near_toggle);
  EXPECT_NEAR(deg(r.mu_min), 1.4e-4, 0.1e-4);
  EXPECT_NEAR(r.min_abs_sin_mu, std::sin(r.mu_min), 1e-18);
  EXPECT_LT(r.min_abs_sin_mu, kNearToggleSine);
  // The law of cosines at |AB0| = d - a gives the same angle independently.
  const double diag = 1.0 - 0.249999999999;
  const double cos_mu = (0.25 * 0.25 + 1.0 - diag * diag) / (2.0 * 0.25 * 1.0);
  EXPECT_NEAR(r.mu_min, std::acos(cos_mu), 1e-7);  // acos loses half the digits next to 1
  // The thesis' beat-up is far from it.
  EXPECT_FALSE(transmission_range(FourBar{0.213, 0.058, 0.189, 0.232}).near_toggle);
}

// Issue 13: the slider-crank at 1e155 (squares overflow) and 1e-155 (squares underflow) gives the
// scaled unit solution, finite; a crank speed whose square overflows is a NaN/inf the caller sees.
TEST(SliderCrankHard, ScaleFreeAtOneE155) {
  const SliderCrank unit_sc{1.0, 3.0, 0.5};
  const SliderDeadCentres d1 = slider_dead_centres(unit_sc);
  for (double k : {1e-155, 1e155}) {
    const SliderCrank m{unit_sc.crank * k, unit_sc.coupler * k, unit_sc.offset * k};
    for (int i = 0; i < 36; ++i) {
      const double t = kTwoPi * i / 36.0;
      const SliderState a = slider_state(m, t, 1.0, 0.0), b = slider_state(unit_sc, t, 1.0, 0.0);
      EXPECT_TRUE(std::isfinite(a.x) && std::isfinite(a.x_dot) && std::isfinite(a.x_ddot)) << k << " " << i;
      EXPECT_NEAR(a.x / k, b.x, 1e-14) << k;
      EXPECT_NEAR(a.x_ddot / k, b.x_ddot, 1e-13) << k;
      EXPECT_NEAR(a.coupler_accel_rad_s2, b.coupler_accel_rad_s2, 1e-13) << k;
      EXPECT_NEAR(a.transmission_rad, b.transmission_rad, 1e-14) << k;
    }
    const SliderDeadCentres d = slider_dead_centres(m);
    EXPECT_NEAR(d.stroke / k, d1.stroke, 1e-14) << k;
    EXPECT_NEAR(d.time_ratio, d1.time_ratio, 1e-14) << k;
    EXPECT_NEAR(d.mu_min_rad, d1.mu_min_rad, 1e-14) << k;
  }
}

// A double-rocker (Grashof, the coupler shortest): the knotting-chain example with links r0 = 78.105
// (ground), r1 = 82.345 (input), r2 = 15.688 (coupler), r3 = 65.426 (output) mm at the pose θ1 = 135°,
// θ2 = 10° in the drawing's frame. Independent values in long double, written out here: the diagonal
// s = r1 + r2, the output angle θ3 = θs + acos((s² + r3² − r0²)/(2 s r3)), the ground direction
// r1 + r2 − r3, and the output rate ω3/ω1 = (r1/r3)·sin(θ1 − θ2)/sin(θ3 − θ2) (−22.851).
TEST(FourBarDoubleRocker, AnalysedAtThePosesItReaches) {
  const FourBar m{78.105, 82.345, 15.688, 65.426};
  ASSERT_EQ(classify(m), GrashofClass::kDoubleRocker);
  const long double d2r = 3.141592653589793238462643383279502884L / 180.0L;
  const long double r0 = 78.105L, r1 = 82.345L, r2 = 15.688L, r3 = 65.426L;
  const long double t1 = 135.0L * d2r, t2 = 10.0L * d2r;
  const long double sx = r1 * std::cos(t1) + r2 * std::cos(t2), sy = r1 * std::sin(t1) + r2 * std::sin(t2);
  const long double s = std::hypot(sx, sy), ts = std::atan2(sy, sx);
  const long double t3 = ts + std::acos((s * s + r3 * r3 - r0 * r0) / (2.0L * s * r3));
  const long double ground = std::atan2(sy - r3 * std::sin(t3), sx - r3 * std::cos(t3));
  const long double w3 = r1 / r3 * std::sin(t1 - t2) / std::sin(t3 - t2);
  const long double w2 = -r1 / r2 * std::sin(t1 - t3) / std::sin(t2 - t3);
  EXPECT_NEAR(static_cast<double>(w3), -22.851, 5e-4);  // the value the chain's example should print
  const double crank = static_cast<double>(t1 - ground);
  const Branch branch = branch_of(static_cast<double>(t2 - ground), static_cast<double>(t3 - ground));
  const FourBarPose p = solve(m, crank, branch);
  EXPECT_NEAR(p.k4, static_cast<double>(w3), 1e-11 * std::fabs(static_cast<double>(w3)));
  EXPECT_NEAR(p.k3, static_cast<double>(w2), 1e-11 * std::fabs(static_cast<double>(w2)));
  EXPECT_NEAR(wrap_pi(p.theta4 - static_cast<double>(t3 - ground)), 0.0, 1e-12);

  // A whole turn: the reachable poses come out, the rest are counted, never thrown.
  std::vector<FourBarPose> poses;
  std::vector<int> index;
  const ReachableSweep cover = fourbar_sweep_reachable(m, branch, 360, 0.0, [&](int i, const FourBarPose& q) {
    index.push_back(i);
    poses.push_back(q);
  });
  EXPECT_EQ(cover.solved + cover.unreachable + cover.at_toggle, 360);
  EXPECT_GT(cover.solved, 0);
  EXPECT_GT(cover.unreachable, 0);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const FourBarPose q = solve(m, kTwoPi * index[k] / 360.0, branch);
    EXPECT_NEAR(poses[k].k4, q.k4, 1e-12 * std::max(1.0, std::fabs(q.k4)));
    // Reachable: A within the annulus |b − c| ≤ |A − B0| ≤ b + c around the output pivot.
    const double ax = m.crank * std::cos(q.theta2) - m.ground, ay = m.crank * std::sin(q.theta2);
    EXPECT_LE(std::hypot(ax, ay), m.coupler + m.rocker + 1e-9);
  }
  // The fully turning classes lose nothing.
  const ReachableSweep full = fourbar_sweep_reachable(FourBar{1.0, 0.3, 1.0, 0.8}, Branch::kPositive, 64, 0.0,
                                                      [](int, const FourBarPose&) {});
  EXPECT_EQ(full.solved, 64);
}
}  // namespace
}  // namespace loom::motion
