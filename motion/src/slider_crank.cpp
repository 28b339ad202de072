// Offset slider-crank analysis (see slider_crank.hpp). Every square root is of a product of factors
// that stay positive for a full-turning crank, and differences of nearly equal lengths are
// rewritten as quotients, so long couplers and near-toggle designs keep their accuracy.
#include "loom/motion/slider_crank.hpp"

#include <cmath>
#include <sstream>

#include "checks.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "scale.hpp"

namespace loom::motion {

namespace {

void check_lengths(const SliderCrank& m) {
  detail::require_positive_length("slider-crank", "crank a", m.crank, "");
  detail::require_positive_length("slider-crank", "coupler b", m.coupler, "");
  detail::require_finite("slider-crank", "offset e", m.offset, "");
}

// Grashof for a slider-crank: the crank turns fully only if the coupler spans crank + |offset|.
// A margin within 1e-12·b of zero is the change point, where the coupler stands perpendicular to
// the slider line and the rates are unbounded: `accept_change_point` admits it for the dead-centre
// analysis, which stays defined there; the state evaluation needs a real margin to stay finite.
void check_full_turn(const SliderCrank& m, bool accept_change_point) {
  const double margin = m.coupler - m.crank - std::fabs(m.offset);
  const double slack = 1e-12 * m.coupler;
  const bool turns = accept_change_point ? margin > -slack : margin > slack;
  if (!turns) {
    std::ostringstream msg;
    msg << "slider-crank: coupler b = " << m.coupler
        << " must exceed crank a + |offset e| = " << m.crank + std::fabs(m.offset)
        << " for a full-turning crank";
    if (std::fabs(margin) <= slack) msg << " (b = a + |e| within 1e-12 b: change point)";
    throw MotionError(ErrorCode::kNotCrank, msg.str());
  }
}

}  // namespace

void validate_slider_crank(const SliderCrank& m) {
  check_lengths(m);
  check_full_turn(m, false);
}

namespace {

// Crank-angle derivatives of the slider-crank's loop: q is the height of the slider line above the
// crank pin, h the coupler's run along the line (h² + q² = b²), x = a cos θ + h, and the coupler
// angle φ3 = atan2(q, h) with dφ3/dθ = q'/h (from h h' = −q q').
struct SliderCoefficients {
  double x, dx, ddx;     // slider position and its θ-derivatives
  double phi3, k3, k3p;  // coupler angle and its θ-derivatives
  double q, h;
};

// Scale-free: the loop is solved in units of L, a power of two near the largest length (so squares and
// products cannot overflow or underflow at any scale a double can hold) and the lengths are scaled back.
SliderCoefficients coefficients(const SliderCrank& m, double theta_rad) noexcept {
  const double L = detail::length_scale(std::fmax(std::fmax(m.crank, m.coupler), std::fabs(m.offset)));
  const double a = m.crank / L;
  const double b = m.coupler / L;
  const double s = std::sin(theta_rad);
  const double c = std::cos(theta_rad);
  SliderCoefficients k{};
  k.q = m.offset / L - a * s;
  k.h = std::sqrt((b - k.q) * (b + k.q));
  const double dq = -a * c;
  const double dh = -k.q * dq / k.h;
  const double ddq = a * s;
  const double ddh = (-(dq * dq) - k.q * ddq - dh * dh) / k.h;  // from h·h'' = −q'² − q·q'' − h'²
  k.x = a * c + k.h;
  k.dx = -a * s + dh;
  k.ddx = -a * c + ddh;
  k.phi3 = std::atan2(k.q, k.h);
  k.k3 = dq / k.h;
  k.k3p = (ddq * k.h - dq * dh) / (k.h * k.h);
  k.x *= L;
  k.dx *= L;
  k.ddx *= L;
  k.q *= L;
  k.h *= L;
  return k;
}

}  // namespace

SliderState slider_state(const SliderCrank& m, double theta_rad, double omega_rad_s,
                         double alpha_rad_s2) noexcept {
  const SliderCoefficients k = coefficients(m, theta_rad);
  SliderState st;
  st.x = k.x;
  st.x_dot = k.dx * omega_rad_s;
  st.x_ddot = k.ddx * omega_rad_s * omega_rad_s + k.dx * alpha_rad_s2;
  st.coupler_angle_rad = k.phi3;
  st.transmission_rad = std::atan2(k.h, std::fabs(k.q));
  st.coupler_rate_rad_s = k.k3 * omega_rad_s;
  st.coupler_accel_rad_s2 = k.k3 * alpha_rad_s2 + k.k3p * omega_rad_s * omega_rad_s;
  return st;
}

PointCoefficients slider_coupler_point(const SliderCrank& m, double theta_rad,
                                       const Eigen::Vector2d& local) noexcept {
  const SliderCoefficients k = coefficients(m, theta_rad);
  const Eigen::Vector2d pin(m.crank * std::cos(theta_rad), m.crank * std::sin(theta_rad));
  const PointCoefficients origin{pin, Eigen::Vector2d(-pin.y(), pin.x()), -pin};
  return point_on_link(origin, k.phi3, k.k3, k.k3p, local);
}

SliderDeadCentres slider_dead_centres(const SliderCrank& m) {
  // In units of L, a power of two near the largest length (scale-free, see coefficients()); lengths scaled
  // back below.
  check_lengths(m);
  const double L = detail::length_scale(std::fmax(std::fmax(m.crank, m.coupler), std::fabs(m.offset)));
  const double a = m.crank / L;
  const double b = m.coupler / L;
  const double e = m.offset / L;
  const double ae = std::fabs(e);
  // The change-point limit b = a + |e| (a flagged synthesis result, maybe a few ulps short) still
  // has well-defined dead centres; anything shorter is rejected as by validate_slider_crank.
  check_lengths(m);
  check_full_turn(m, true);
  const double fold_margin = std::fmax(0.0, b - a - ae);

  SliderDeadCentres dc;
  dc.x_extended = std::sqrt((a + b - ae) * (a + b + ae));
  dc.x_folded = std::sqrt(fold_margin * (b - a + ae));
  // x_e − x_f = ((a+b)² − (b−a)²) / (x_e + x_f): no cancellation when b ≫ a.
  dc.stroke = 4.0 * a * b / (dc.x_extended + dc.x_folded);

  // Directions of B from A0 at the dead centres; the folded crank points the opposite way.
  const double dir_extended = std::atan2(e, dc.x_extended);
  const double dir_folded = std::atan2(e, dc.x_folded);
  dc.theta_extended_rad = wrap_two_pi(dir_extended);
  dc.theta_folded_rad = wrap_two_pi(dir_folded + kPi);
  // dir_folded − dir_extended = atan(e/x_f) − atan(e/x_e), as one atan2 of exact-sign terms.
  const double spread = std::atan2(e * dc.stroke, dc.x_extended * dc.x_folded + e * e);
  dc.phi_extend_to_fold_rad = kPi + spread;
  dc.phi_fold_to_extend_rad = kPi - spread;
  dc.phi_half_difference_rad = spread;
  const double longer = std::fmax(dc.phi_extend_to_fold_rad, dc.phi_fold_to_extend_rad);
  const double shorter = std::fmin(dc.phi_extend_to_fold_rad, dc.phi_fold_to_extend_rad);
  dc.time_ratio = longer / shorter;

  // The coupler leans most when the crank pin is farthest from the slider line (|q| = a + |e|).
  dc.mu_min_rad = std::atan2(std::sqrt(fold_margin * (b + a + ae)), a + ae);
  dc.theta_mu_min_rad = e < 0.0 ? 0.5 * kPi : 1.5 * kPi;
  dc.x_extended *= L;
  dc.x_folded *= L;
  dc.stroke *= L;
  return dc;
}

}  // namespace loom::motion
