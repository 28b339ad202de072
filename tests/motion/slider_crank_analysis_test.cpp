// Offset slider-crank analysis against independent truth: finite differences of the position for
// velocity and acceleration, a golden-section search of the slider's extremes for the dead
// centres and stroke, dense sampling for μ_min, and long-double closed forms for long couplers.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/slider_crank.hpp"

namespace {

using loom::motion::ErrorCode;
using loom::motion::kPi;
using loom::motion::kTwoPi;
using loom::motion::MotionError;
using loom::motion::SliderCrank;

// Position written out independently of the library: B = (a cos θ + √(b² − (e − a sin θ)²), e).
double slider_x(const SliderCrank& m, double theta) {
  const double q = m.offset - m.crank * std::sin(theta);
  return m.crank * std::cos(theta) + std::sqrt(m.coupler * m.coupler - q * q);
}

// Golden-section search for an extremum of slider_x on [lo, hi] (sign = +1 max, −1 min).
double golden_extremum(const SliderCrank& m, double lo, double hi, double sign) {
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
  double f1 = sign * slider_x(m, x1), f2 = sign * slider_x(m, x2);
  for (int i = 0; i < 200; ++i) {
    if (f1 > f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - r * (hi - lo);
      f1 = sign * slider_x(m, x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + r * (hi - lo);
      f2 = sign * slider_x(m, x2);
    }
  }
  return 0.5 * (lo + hi);
}

const std::vector<SliderCrank>& mechanisms() {
  static const std::vector<SliderCrank> ms = {
      {0.478817, 1.576817, 0.430672},  // thesis Table 4.2, φ = 169°
      {0.3, 1.0, -0.2},                // negative offset
      {0.25, 0.9, 0.0},                // centric
      {0.05, 3.0, 1.2},                // tiny crank, large offset
      {0.9, 1.0, 0.05},                // near toggle: b − a − e = 0.05
  };
  return ms;
}

TEST(SliderCrankAnalysis, RejectsBadGeometryWithTypedErrors) {
  auto code_of = [](SliderCrank m) {
    try {
      loom::motion::validate_slider_crank(m);
    } catch (const MotionError& e) {
      return static_cast<int>(e.code());
    }
    return -1;
  };
  EXPECT_EQ(code_of({0.0, 1.0, 0.0}), static_cast<int>(ErrorCode::kInvalidInput));
  EXPECT_EQ(code_of({0.2, -1.0, 0.0}), static_cast<int>(ErrorCode::kInvalidInput));
  EXPECT_EQ(code_of({0.2, 1.0, std::nan("")}), static_cast<int>(ErrorCode::kInvalidInput));
  EXPECT_EQ(code_of({0.5, 1.0, 0.5}), static_cast<int>(ErrorCode::kNotCrank));   // b = a + e
  EXPECT_EQ(code_of({0.5, 1.0, -0.6}), static_cast<int>(ErrorCode::kNotCrank));  // b < a + |e|
  EXPECT_EQ(code_of({0.5, 1.0, 0.4}), -1);
  // The dead-centre analysis accepts the change-point limit, the state evaluation does not.
  const auto dc = loom::motion::slider_dead_centres({0.5, 1.0, 0.5});
  EXPECT_DOUBLE_EQ(dc.mu_min_rad, 0.0);
  EXPECT_THROW(loom::motion::slider_dead_centres({0.5, 1.0, 0.6}), MotionError);
}

TEST(SliderCrankAnalysis, VelocityAndAccelerationMatchFiniteDifferences) {
  // Crank law θ(t) = θ0 + ω t + α t²/2; compare with central differences of x(t) in time.
  const double omega = 2.3, alpha = -1.7, dt = 1e-4;
  for (const SliderCrank& m : mechanisms()) {
    for (int i = 0; i < 72; ++i) {
      const double th0 = kTwoPi * i / 72.0 + 0.01;
      auto theta_at = [&](double t) { return th0 + omega * t + 0.5 * alpha * t * t; };
      const auto s = loom::motion::slider_state(m, th0, omega, alpha);
      const double xp = slider_x(m, theta_at(dt)), xm = slider_x(m, theta_at(-dt));
      const double x0 = slider_x(m, th0);
      const double v_fd = (xp - xm) / (2 * dt);
      const double a_fd = (xp - 2 * x0 + xm) / (dt * dt);
      const double scale = m.crank * (omega * omega + std::fabs(alpha) + omega);
      EXPECT_NEAR(s.x, x0, 1e-14) << "theta " << th0;
      EXPECT_NEAR(s.x_dot, v_fd, 1e-6 * scale) << "theta " << th0;
      EXPECT_NEAR(s.x_ddot, a_fd, 1e-6 * scale * 10) << "theta " << th0;
      // Transmission angle: acos(|e − a sin θ| / b), the thesis' eq. 4.18.
      const double mu = std::acos(std::fabs(m.offset - m.crank * std::sin(th0)) / m.coupler);
      EXPECT_NEAR(s.transmission_rad, mu, 1e-12);
    }
  }
}

TEST(SliderCrankAnalysis, DeadCentresAreTheSlidersExtremes) {
  for (const SliderCrank& m : mechanisms()) {
    const auto dc = loom::motion::slider_dead_centres(m);
    // Bracket each extremum around its reported crank angle and search independently.
    const double th_max = golden_extremum(m, dc.theta_extended_rad - 0.5, dc.theta_extended_rad + 0.5, +1);
    const double th_min = golden_extremum(m, dc.theta_folded_rad - 0.5, dc.theta_folded_rad + 0.5, -1);
    EXPECT_NEAR(dc.theta_extended_rad, th_max, 1e-7);
    EXPECT_NEAR(dc.theta_folded_rad, th_min, 1e-7);
    EXPECT_NEAR(dc.x_extended, slider_x(m, th_max), 1e-13);
    EXPECT_NEAR(dc.x_folded, slider_x(m, th_min), 1e-13);
    EXPECT_NEAR(dc.stroke, slider_x(m, th_max) - slider_x(m, th_min), 1e-13);
    EXPECT_NEAR(dc.phi_extend_to_fold_rad, loom::motion::wrap_two_pi(th_min - th_max), 2e-7);
    EXPECT_NEAR(dc.phi_extend_to_fold_rad + dc.phi_fold_to_extend_rad, kTwoPi, 1e-14);
    EXPECT_GE(dc.time_ratio, 1.0);

    double mu_sampled = kPi;
    for (int i = 0; i <= 200000; ++i) {
      const double th = kTwoPi * i / 200000.0;
      mu_sampled = std::fmin(mu_sampled, loom::motion::slider_state(m, th, 1, 0).transmission_rad);
    }
    EXPECT_NEAR(dc.mu_min_rad, mu_sampled, 1e-9);
    EXPECT_NEAR(loom::motion::slider_state(m, dc.theta_mu_min_rad, 1, 0).transmission_rad, dc.mu_min_rad,
                1e-12);
  }
}

TEST(SliderCrankAnalysis, LongCouplerKeepsStrokeAndRotationAccurate) {
  // b = 1e6·a: the naive x_e − x_f loses six digits; compare with long double closed forms.
  const SliderCrank m{1.0, 1e6, 0.3};
  const auto dc = loom::motion::slider_dead_centres(m);
  const long double a = 1.0L, b = 1e6L, e = 0.3L;
  const long double xe = std::sqrt((a + b) * (a + b) - e * e);
  const long double xf = std::sqrt((b - a) * (b - a) - e * e);
  EXPECT_NEAR(dc.stroke, static_cast<double>(xe - xf), 1e-12);
  const long double spread = std::atan(e / xf) - std::atan(e / xe);
  EXPECT_NEAR(dc.phi_half_difference_rad / static_cast<double>(spread), 1.0, 1e-12);
  EXPECT_NEAR(dc.phi_fold_to_extend_rad, kPi - static_cast<double>(spread), 1e-15);
}

TEST(SliderCrankAnalysis, TinyCrankKeepsRelativeAccuracy) {
  // a = 1e-9·b: stroke = 2ab/√(b² − e²)·(1 + O(a²/b²)), an independent series with error ~1e-18.
  const SliderCrank m{1e-9, 1.0, 0.3};
  const auto dc = loom::motion::slider_dead_centres(m);
  const double series = 2.0 * m.crank * m.coupler / std::sqrt(1.0 - 0.09);
  EXPECT_NEAR(dc.stroke / series, 1.0, 1e-12);
  EXPECT_TRUE(std::isfinite(dc.mu_min_rad) && std::isfinite(dc.time_ratio));
  for (int i = 0; i < 16; ++i) {
    const double th = kTwoPi * i / 16.0;
    const auto st = loom::motion::slider_state(m, th, 1.0, 0.0);
    EXPECT_TRUE(std::isfinite(st.x) && std::isfinite(st.x_dot) && std::isfinite(st.x_ddot));
    // To first order in a: dx/dθ = a(−sin θ + e cos θ / √(b² − e²)), d²x/dθ² its derivative;
    // the neglected terms are O(a²) (e.g. −a²(1 + e²/h²)/h at θ = 0).
    const double h0 = std::sqrt(1.0 - 0.09);
    const double tol = 5.0 * m.crank * m.crank + 1e-15 * m.crank;
    EXPECT_NEAR(st.x_dot, m.crank * (-std::sin(th) + 0.3 * std::cos(th) / h0), tol);
    EXPECT_NEAR(st.x_ddot, m.crank * (-std::cos(th) - 0.3 * std::sin(th) / h0), tol);
  }
}

}  // namespace
