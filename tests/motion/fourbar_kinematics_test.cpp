// Four-bar and slider-crank kinematics beyond the link angles (issue 6 §1), against independent
// truth: points on every link rebuilt from the joints and differentiated numerically in time under
// an accelerating crank, whole-turn sweeps against the coefficients they carry, transmission-angle
// extremes against dense sampling, time ratios against golden-section searches, and Newton against
// the closed form on both branches.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include "finite_diff.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/slider_crank.hpp"
#include "motion_error.hpp"

namespace loom::motion {
namespace {

using Eigen::Vector2d;

// Thesis Table 5.1 beat-up, a drag link and a long-coupler crank-rocker with a poor transmission.
const FourBar kBeatUp{.ground = 0.213, .crank = 0.058, .coupler = 0.189, .rocker = 0.232};
const FourBar kDragLink{.ground = 1.0, .crank = 3.0, .coupler = 3.5, .rocker = 3.2};
const FourBar kLean{.ground = 1.0, .crank = 0.2, .coupler = 2.9, .rocker = 2.2};

Vector2d rotate(double angle, const Vector2d& v) {
  return {std::cos(angle) * v.x() - std::sin(angle) * v.y(),
          std::sin(angle) * v.x() + std::cos(angle) * v.y()};
}

// The point rebuilt from the joints alone: A from the crank angle, B from the rocker angle.
Vector2d point_from_joints(const FourBar& m, const FourBarPose& p, FourBarLink link, const Vector2d& local) {
  const Vector2d a(m.crank * std::cos(p.theta2), m.crank * std::sin(p.theta2));
  const Vector2d b0(m.ground, 0.0);
  const Vector2d b = b0 + m.rocker * Vector2d(std::cos(p.theta4), std::sin(p.theta4));
  switch (link) {
    case FourBarLink::kCrank:
      return rotate(p.theta2, local);
    case FourBarLink::kCoupler:
      return a + rotate(std::atan2(b.y() - a.y(), b.x() - a.x()), local);
    case FourBarLink::kRocker:
      return b0 + rotate(p.theta4, local);
  }
  return {};
}

using test::error_of;

struct CrankLaw {  // θ2(t) = θ0 + ω0 t + α t²/2
  double theta0, omega0, alpha;
  double angle(double t) const { return theta0 + omega0 * t + 0.5 * alpha * t * t; }
  double rate(double t) const { return omega0 + alpha * t; }
};

TEST(FourBarPoints, JointsComeOutWhereTheLoopPutsThem) {
  for (const FourBar& m : {kBeatUp, kDragLink, kLean}) {
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      for (int i = 0; i < 360; i += 5) {
        const FourBarPose p = solve(m, rad(i), br);
        // The coupler's far end and the rocker's far end are the same pin B.
        const Vector2d b_coupler = point_coefficients(m, p, FourBarLink::kCoupler, {m.coupler, 0.0}).position;
        const Vector2d b_rocker = point_coefficients(m, p, FourBarLink::kRocker, {m.rocker, 0.0}).position;
        const Vector2d a_crank = point_coefficients(m, p, FourBarLink::kCrank, {m.crank, 0.0}).position;
        const Vector2d a_coupler = point_coefficients(m, p, FourBarLink::kCoupler, {0.0, 0.0}).position;
        EXPECT_LE((b_coupler - b_rocker).norm(), 1e-12 * m.rocker + 1e-12 * m.coupler) << i;
        EXPECT_LE((a_crank - a_coupler).norm(), 1e-15 * m.crank) << i;
        // Pins have the speeds their pivots allow: B moves perpendicular to B0B, A to A0A.
        const PointCoefficients b = point_coefficients(m, p, FourBarLink::kRocker, {m.rocker, 0.0});
        EXPECT_NEAR(b.d1.dot(b.position - Vector2d(m.ground, 0.0)), 0.0,
                    1e-12 * m.rocker * m.rocker * (1 + std::abs(p.k4)));
      }
    }
  }
}

TEST(FourBarPoints, VelocityAndAccelerationMatchFiniteDifferencesInTime) {
  // Points off the link lines too: a beater tip, a coupler point, a crank counterweight.
  const std::array<std::pair<FourBarLink, Vector2d>, 4> points{{{FourBarLink::kRocker, {0.301, 0.0}},
                                                                {FourBarLink::kRocker, {0.15, -0.04}},
                                                                {FourBarLink::kCoupler, {0.07, 0.05}},
                                                                {FourBarLink::kCrank, {-0.03, 0.01}}}};
  for (const FourBar& m : {kBeatUp, kLean}) {
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      for (const CrankLaw law : {CrankLaw{0.2, 15.5, 0.0}, CrankLaw{0.2, 15.5, -40.0}}) {
        for (const auto& [link, local] : points) {
          const auto at = [&](double t) { return solve(m, law.angle(t), br); };
          const double period = kTwoPi / law.omega0;
          double vmax = 0.0, amax = 0.0;
          std::vector<PointMotion> exact;
          for (int i = 0; i < 72; ++i) {
            const double t = period * i / 72.0;
            exact.push_back(point_motion(point_coefficients(m, at(t), link, local), law.rate(t), law.alpha));
            vmax = std::max(vmax, exact.back().velocity.norm());
            amax = std::max(amax, exact.back().acceleration.norm());
          }
          const double h = 1e-3 / law.omega0;
          for (int i = 0; i < 72; ++i) {
            const double t0 = period * i / 72.0;
            for (int axis = 0; axis < 2; ++axis) {
              const auto coord = [&](double t) { return point_from_joints(m, at(t), link, local)(axis); };
              EXPECT_NEAR(exact[i].position(axis), coord(t0), 1e-12 * m.ground);
              EXPECT_TRUE(test::close_rel(exact[i].velocity(axis), test::d1(coord, t0, h), vmax, 1e-6))
                  << "v axis " << axis << " t " << t0;
              EXPECT_TRUE(test::close_rel(exact[i].acceleration(axis), test::d2(coord, t0, h), amax, 1e-6))
                  << "a axis " << axis << " t " << t0;
            }
          }
        }
      }
    }
  }
}

TEST(SliderCrankPoints, CouplerRatesAndPointsMatchFiniteDifferences) {
  const SliderCrank m{0.3, 1.0, -0.2};
  const CrankLaw law{0.1, 2.3, -1.7};
  const auto state = [&](double t) { return slider_state(m, law.angle(t), law.rate(t), law.alpha); };
  const auto coupler_angle = [&](double t) { return state(t).coupler_angle_rad; };
  const Vector2d local(0.4, 0.12);
  const auto point = [&](double t, int axis) {
    // Rebuilt from the slider pin alone: B = (x, e), coupler direction A → B.
    const double th = law.angle(t);
    const Vector2d a(m.crank * std::cos(th), m.crank * std::sin(th));
    const Vector2d b(slider_state(m, th, 0, 0).x, m.offset);
    return (a + rotate(std::atan2(b.y() - a.y(), b.x() - a.x()), local))(axis);
  };
  const double h = 1e-4;
  for (int i = 0; i < 72; ++i) {
    const double t0 = 0.05 * i;
    const SliderState s = state(t0);
    EXPECT_NEAR(s.coupler_rate_rad_s, test::d1(coupler_angle, t0, h), 1e-8);
    EXPECT_NEAR(s.coupler_accel_rad_s2, test::d2(coupler_angle, t0, h), 1e-6);
    const PointMotion pm =
        point_motion(slider_coupler_point(m, law.angle(t0), local), law.rate(t0), law.alpha);
    // The coupler's far end is the slider pin, which moves along the slider line only.
    const PointCoefficients pin = slider_coupler_point(m, law.angle(t0), {m.coupler, 0.0});
    EXPECT_NEAR(pin.position.x(), slider_state(m, law.angle(t0), 0, 0).x, 1e-14);
    EXPECT_NEAR(pin.position.y(), m.offset, 1e-14);
    EXPECT_NEAR(pin.d1.y(), 0.0, 1e-14);
    EXPECT_NEAR(pin.d2.y(), 0.0, 1e-13);
    for (int axis = 0; axis < 2; ++axis) {
      const auto coord = [&](double t) { return point(t, axis); };
      EXPECT_NEAR(pm.position(axis), coord(t0), 1e-14);
      EXPECT_NEAR(pm.velocity(axis), test::d1(coord, t0, h), 1e-8);
      EXPECT_NEAR(pm.acceleration(axis), test::d2(coord, t0, h), 1e-6);
    }
  }
}

TEST(FourBarSweep, OneTurnIsContinuousAndClosesOnItself) {
  for (Branch br : {Branch::kPositive, Branch::kNegative}) {
    for (const FourBar& m : {kBeatUp, kLean, kDragLink}) {
      const int n = 3600;
      const std::vector<FourBarPose> sw = fourbar_sweep(m, br, n, 0.25);
      ASSERT_EQ(sw.size(), static_cast<std::size_t>(n));
      double k4_max = 0.0, k3_max = 0.0;
      for (const FourBarPose& p : sw) {
        k4_max = std::max(k4_max, std::abs(p.k4));
        k3_max = std::max(k3_max, std::abs(p.k3));
      }
      const double dt2 = kTwoPi / n;
      double integral4 = 0.0, integral3 = 0.0;
      for (int i = 1; i < n; ++i) {
        // No jump larger than the steepest slope allows (a branch flip would be ~2γ).
        EXPECT_LE(std::abs(sw[i].theta4 - sw[i - 1].theta4), 1.01 * k4_max * dt2);
        EXPECT_LE(std::abs(sw[i].theta3 - sw[i - 1].theta3), 1.01 * k3_max * dt2);
        integral4 += 0.5 * (sw[i].k4 + sw[i - 1].k4) * dt2;
        integral3 += 0.5 * (sw[i].k3 + sw[i - 1].k3) * dt2;
        EXPECT_EQ(branch_of(sw[i].theta3, sw[i].theta4), br);
      }
      // The integrated coefficients reproduce the unwrapped angles (trapezoid error ~ dt²).
      EXPECT_NEAR(integral4, sw.back().theta4 - sw.front().theta4, 1e-5);
      EXPECT_NEAR(integral3, sw.back().theta3 - sw.front().theta3, 1e-5);
      // One turn later the linkage is where it started; a drag link's output has turned once.
      const FourBarPose again = solve(m, 0.25 + kTwoPi, br);
      const double turns = classify(m) == GrashofClass::kDoubleCrank ? kTwoPi : 0.0;
      const double end4 = sw.back().theta4 + wrap_pi(again.theta4 - sw.back().theta4);
      EXPECT_NEAR(end4 - sw.front().theta4, turns, 1e-9);
    }
  }
}

TEST(FourBarSweep, RefusesWhatCannotTurnOrFoldsFlat) {
  const auto code = [](const FourBar& m, int samples) {
    return error_of([&] { (void)fourbar_sweep(m, Branch::kPositive, samples); });
  };
  EXPECT_EQ(code({.ground = 3, .crank = 3.5, .coupler = 1, .rocker = 3.2}, 10), ErrorCode::kNotCrank);
  EXPECT_EQ(code({.ground = 1, .crank = 2, .coupler = 3, .rocker = 5}, 10), ErrorCode::kNotCrank);
  EXPECT_EQ(code({.ground = 2, .crank = 1, .coupler = 2, .rocker = 1}, 10), ErrorCode::kSingular);
  EXPECT_EQ(code(kBeatUp, 0), ErrorCode::kInvalidInput);
  EXPECT_THROW((void)fourbar_sweep(kBeatUp, Branch::kPositive, 10, std::nan("")), MotionError);
}

TEST(FourBarTransmission, ExtremesMatchDenseSamplingOnBothBranches) {
  for (const FourBar& m : {kBeatUp, kLean, kDragLink}) {
    const TransmissionRange r = transmission_range(m);
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      double lo = kPi, hi = 0.0;
      for (int i = 0; i < 100000; ++i) {
        const double mu = solve(m, kTwoPi * i / 100000.0, br).transmission;
        lo = std::min(lo, mu);
        hi = std::max(hi, mu);
      }
      EXPECT_NEAR(r.mu_min, lo, 1e-12);  // the sample grid contains θ2 = 0 and π exactly
      EXPECT_NEAR(r.mu_max, hi, 1e-12);
    }
    EXPECT_NEAR(r.worst_deviation_from_right, std::max(kPi / 2 - r.mu_min, r.mu_max - kPi / 2), 1e-15);
  }
  EXPECT_NEAR(dead_centres(kBeatUp, Branch::kPositive).mu_min,
              kPi / 2 - transmission_range(kBeatUp).worst_deviation_from_right, 1e-15);
  EXPECT_THROW((void)transmission_range({.ground = 3, .crank = 3.5, .coupler = 1, .rocker = 3.2}),
               MotionError);
}

// Golden-section search for an extremum of f on [lo, hi] (sign = +1 max, −1 min).
double golden(const std::function<double(double)>& f, double lo, double hi, double sign) {
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
  double f1 = sign * f(x1), f2 = sign * f(x2);
  for (int i = 0; i < 200; ++i) {
    if (f1 > f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - r * (hi - lo), f1 = sign * f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + r * (hi - lo), f2 = sign * f(x2);
    }
  }
  return 0.5 * (lo + hi);
}

TEST(TimeRatio, FourBarAndSliderCrankAgreeWithTheirOutputsExtremes) {
  for (const FourBar& m : {kBeatUp, kLean}) {
    const DeadCentres dc = dead_centres(m, Branch::kPositive);
    // The rocker's own extremes, found by search on θ4(θ2) around the reported dead centres.
    const auto theta4 = [&](double t) { return solve(m, t, Branch::kPositive).theta4; };
    const double ext = golden(theta4, dc.crank_extended - 0.5, dc.crank_extended + 0.5,
                              theta4(dc.crank_extended) > theta4(dc.crank_extended + 0.3) ? 1 : -1);
    const double fold = golden(theta4, dc.crank_folded - 0.5, dc.crank_folded + 0.5,
                               theta4(dc.crank_folded) > theta4(dc.crank_folded + 0.3) ? 1 : -1);
    const double phi = wrap_two_pi(fold - ext);
    EXPECT_NEAR(dc.crank_rotation, phi, 1e-7);
    EXPECT_NEAR(dc.time_ratio, phi / (kTwoPi - phi), 1e-6);
  }
  for (const SliderCrank& s :
       {SliderCrank{0.3, 1.0, 0.2}, SliderCrank{0.3, 1.0, -0.2}, SliderCrank{0.478817, 1.576817, 0.430672}}) {
    const SliderDeadCentres dc = slider_dead_centres(s);
    const auto x = [&](double t) { return slider_state(s, t, 0, 0).x; };
    const double far = golden(x, dc.theta_extended_rad - 0.5, dc.theta_extended_rad + 0.5, 1);
    const double near = golden(x, dc.theta_folded_rad - 0.5, dc.theta_folded_rad + 0.5, -1);
    const double out = wrap_two_pi(near - far), back = kTwoPi - out;
    EXPECT_NEAR(dc.time_ratio, std::max(out, back) / std::min(out, back), 1e-6);
  }
}

TEST(FourBarNewton, AgreesWithTheClosedFormOnBothBranches) {
  for (const FourBar& m : {kBeatUp, kLean, kDragLink}) {
    for (Branch br : {Branch::kPositive, Branch::kNegative}) {
      for (int i = 0; i < 360; i += 10) {
        const FourBarPose cf = solve(m, rad(i), br);
        const FourBarNewtonResult n = solve_newton(m, rad(i), br, cf.theta3 + 0.1, cf.theta4 - 0.1);
        EXPECT_NEAR(wrap_pi(n.pose.theta3 - cf.theta3), 0.0, 1e-12);
        EXPECT_NEAR(wrap_pi(n.pose.theta4 - cf.theta4), 0.0, 1e-12);
        EXPECT_NEAR(n.pose.k4, cf.k4, 1e-10 * std::max(1.0, std::abs(cf.k4)));
        EXPECT_LE(n.residual, 1e-13 * std::max({m.ground, m.crank, m.coupler, m.rocker}));
        EXPECT_GE(n.iterations, 1);
      }
    }
  }
}

TEST(FourBarNewton, MirrorGuessBudgetAndBadOptionsAreTypedErrors) {
  const auto code = [](auto&& f) { return error_of(f); };
  for (int i = 0; i < 360; i += 30) {
    const FourBarPose mirror = solve(kBeatUp, rad(i), Branch::kNegative);
    EXPECT_EQ(
        code([&] { (void)solve_newton(kBeatUp, rad(i), Branch::kPositive, mirror.theta3, mirror.theta4); }),
        ErrorCode::kWrongBranch)
        << i;
  }
  const FourBarPose p = solve(kBeatUp, 1.0, Branch::kPositive);
  EXPECT_EQ(code([&] {
              (void)solve_newton(kBeatUp, 1.0, Branch::kPositive, p.theta3 + 0.4, p.theta4,
                                 NewtonOptions{1e-13, 1});
            }),
            ErrorCode::kNoConvergence);
  // θ3 = θ4 puts the Jacobian b·c·sin(θ3 − θ4) at exactly zero.
  EXPECT_EQ(code([&] { (void)solve_newton(kBeatUp, 1.0, Branch::kPositive, 0.7, 0.7); }),
            ErrorCode::kSingular);
  EXPECT_EQ(
      code([&] {
        (void)solve_newton(kBeatUp, 1.0, Branch::kPositive, p.theta3, p.theta4, NewtonOptions{1e-17, 50});
      }),
      ErrorCode::kInvalidInput);
  EXPECT_EQ(code([&] { (void)solve_newton(kBeatUp, 1.0, Branch::kPositive, std::nan(""), p.theta4); }),
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace loom::motion
