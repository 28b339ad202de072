// Offset slider-crank analysis (see slider_crank.hpp). Every square root is of a product of factors
// that stay positive for a full-turning crank, and differences of nearly equal lengths are
// rewritten as quotients, so long couplers and near-toggle designs keep their accuracy.
#include "loom/motion/slider_crank.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

void require_positive_length(const char* name, double v) {
  if (!std::isfinite(v) || !(v > 0.0)) {
    std::ostringstream msg;
    msg << "slider-crank: " << name << " = " << v << " must be a finite length > 0";
    throw MotionError(ErrorCode::kInvalidInput, msg.str());
  }
}

void check_lengths(const SliderCrank& m) {
  require_positive_length("crank a", m.crank);
  require_positive_length("coupler b", m.coupler);
  if (!std::isfinite(m.offset)) {
    std::ostringstream msg;
    msg << "slider-crank: offset e = " << m.offset << " must be finite";
    throw MotionError(ErrorCode::kInvalidInput, msg.str());
  }
}

// Grashof for a slider-crank: the crank turns fully only if the coupler spans crank + |offset|.
// `slack` admits the change-point limit for the dead-centre analysis.
void check_full_turn(const SliderCrank& m, double slack) {
  const double margin = m.coupler - m.crank - std::fabs(m.offset);
  const bool turns = slack > 0.0 ? margin > -slack : margin > 0.0;
  if (!turns) {
    std::ostringstream msg;
    msg << "slider-crank: coupler b = " << m.coupler << " must exceed crank a + |offset e| = "
        << m.crank + std::fabs(m.offset) << " for a full-turning crank";
    throw MotionError(ErrorCode::kNotCrank, msg.str());
  }
}

}  // namespace

void validate_slider_crank(const SliderCrank& m) {
  check_lengths(m);
  check_full_turn(m, 0.0);
}

SliderState slider_state(const SliderCrank& m, double theta_rad, double omega_rad_s,
                         double alpha_rad_s2) noexcept {
  const double a = m.crank;
  const double b = m.coupler;
  const double s = std::sin(theta_rad);
  const double c = std::cos(theta_rad);
  // q: height of the slider line above the crank pin; h: the coupler's run along the line.
  const double q = m.offset - a * s;
  const double h = std::sqrt((b - q) * (b + q));
  const double dq = -a * c;
  const double dh = -q * dq / h;
  const double ddq = a * s;
  const double ddh = (-(dq * dq) - q * ddq - dh * dh) / h;  // from h·h'' = −q'² − q·q'' − h'²

  SliderState st;
  st.x = a * c + h;
  const double dx = -a * s + dh;
  const double ddx = -a * c + ddh;
  st.x_dot = dx * omega_rad_s;
  st.x_ddot = ddx * omega_rad_s * omega_rad_s + dx * alpha_rad_s2;
  st.coupler_angle_rad = std::atan2(q, h);
  st.transmission_rad = std::atan2(h, std::fabs(q));
  return st;
}

SliderDeadCentres slider_dead_centres(const SliderCrank& m) {
  const double a = m.crank;
  const double b = m.coupler;
  const double e = m.offset;
  const double ae = std::fabs(e);
  // The change-point limit b = a + |e| (a flagged synthesis result, maybe a few ulps short) still
  // has well-defined dead centres; anything shorter is rejected as by validate_slider_crank.
  check_lengths(m);
  check_full_turn(m, 1e-12 * b);
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
  return dc;
}

}  // namespace loom::motion
