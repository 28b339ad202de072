// Crank-and-two-rocker batten linkage of seed 004, eqns (7): validation, closed-form positions,
// residual and Jacobian, branch classification and exact rates. Eqns (7) are used as printed (with
// -sin(φ2 - π/2) = cos φ2 and cos(φ2 - π/2) = sin φ2); loop 1 is a four-bar O1-A-B-O3 and loop 2 the
// four-bar O3-B-D-P driven by the rocker L3, so the Jacobian is block lower-triangular.
#include "loom/motion/design/batten.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "checks.hpp"
#include "geometry.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

constexpr const char* kWho = "batten linkage";

Eigen::Vector2d rocker_pivot(const BattenDims& d) {
  return {-d.l7_m, d.l6_m};
}
Eigen::Vector2d batten_pivot(const BattenDims& d) {
  return {d.l9_m, 2.0 * d.l6_m + d.l8_m};
}

}  // namespace

BattenDims batten_004_dims() {
  return BattenDims{0.04, 0.09, 0.08, 0.09, 0.17, 0.1, 0.06, 0.05, 0.11};
}

BattenLinkage::BattenLinkage(const BattenDims& dims, BattenBranch branch) : d_(dims), branch_(branch) {
  static constexpr const char* kLinks[5] = {"L1", "L2", "L3", "L4", "L5"};
  const double links[5] = {d_.l1_m, d_.l2_m, d_.l3_m, d_.l4_m, d_.l5_m};
  for (int i = 0; i < 5; ++i) detail::require_positive_length(kWho, kLinks[i], links[i]);
  detail::require_finite(kWho, "L6", d_.l6_m, " m");
  detail::require_finite(kWho, "L7", d_.l7_m, " m");
  detail::require_finite(kWho, "L8", d_.l8_m, " m");
  detail::require_finite(kWho, "L9", d_.l9_m, " m");

  const Eigen::Vector2d o1(0.0, 0.0);
  const Eigen::Vector2d o3 = rocker_pivot(d_);
  const Eigen::Vector2d p = batten_pivot(d_);
  const double g1 = o3.norm();
  const double g2 = (p - o3).norm();
  scale_m_ = std::max({d_.l1_m, d_.l2_m, d_.l3_m, d_.l4_m, d_.l5_m, g1, g2});
  const double tol = 1e-12 * scale_m_;

  // Loop 1 must be a crank-rocker with L1 the crank (shorter than the ground O1O3, so L3 rocks).
  const detail::CrankTurn turn = detail::crank_turn(g1, d_.l1_m, d_.l2_m, d_.l3_m);
  if (d_.l1_m >= g1 || turn == detail::CrankTurn::kBlocked) {
    std::ostringstream os;
    os << "L1 = " << d_.l1_m << " m cannot turn fully: a crank-rocker needs L1 < |O1O3| = " << g1
       << " m (from L6, L7), |O1O3| - L1 > |L2 - L3| and |O1O3| + L1 < L2 + L3";
    detail::fail(kWho, ErrorCode::kNotCrank, os.str());
  }
  if (turn == detail::CrankTurn::kChangePoint) {
    detail::fail(kWho, ErrorCode::kSingular,
                 "loop 1 is a change-point four-bar (|O1O3| ± L1 equals L2 ± L3)");
  }

  // L3 swing limits at loop 1's dead centres. Loop 1's side is named along A -> O3, the shared
  // four-bar helper's along O3 -> A: the opposite side.
  const bool left1 = branch_.loop1 == LoopSide::kLeft;
  const detail::DeadCentrePins pins = detail::dead_centre_pins(o1, o3, d_.l1_m, d_.l2_m, d_.l3_m, !left1);
  limits_.extended_rad = std::atan2(pins.extended.y() - o3.y(), pins.extended.x() - o3.x());
  limits_.folded_rad = std::atan2(pins.folded.y() - o3.y(), pins.folded.x() - o3.x());

  // Loop 2 closes iff |BP| stays strictly inside (|L5 - L4|, L4 + L5) over the swing. With
  // |BP|² = L3² + g2² - 2 L3 g2 cos(γ3 - angle(O3P)) its extremes follow from cos over the arc.
  const Eigen::Vector2d a0(d_.l1_m, 0.0);
  const Eigen::Vector2d b0 = detail::rocker_pin(o3, d_.l3_m, a0, d_.l2_m, !left1).point;
  const double ref = std::atan2(b0.y() - o3.y(), b0.x() - o3.x());
  const double da = wrap_pi(limits_.extended_rad - ref);
  const double db = wrap_pi(limits_.folded_rad - ref);
  const double phase_p = std::atan2(p.y() - o3.y(), p.x() - o3.x());
  const detail::CosRange cr =
      detail::cos_range(ref + std::min(da, db) - phase_p, ref + std::max(da, db) - phase_p);
  const double l3 = d_.l3_m;
  const double bp_min = std::sqrt(std::max(0.0, l3 * l3 + g2 * g2 - 2.0 * l3 * g2 * cr.max));
  const double bp_max = std::sqrt(l3 * l3 + g2 * g2 - 2.0 * l3 * g2 * cr.min);
  const double lo = std::abs(d_.l5_m - d_.l4_m);
  const double hi = d_.l4_m + d_.l5_m;
  if (bp_min < lo - tol || bp_max > hi + tol) {
    std::ostringstream os;
    os << "loop 2 cannot close: over the L3 swing |BP| spans [" << bp_min << ", " << bp_max
       << "] m but L4 = " << d_.l4_m << " m and L5 = " << d_.l5_m << " m reach only [" << lo << ", " << hi
       << "] m";
    detail::fail(kWho, ErrorCode::kNotAssemblable, os.str());
  }
  if (bp_min <= lo + tol || bp_max >= hi - tol) {
    detail::fail(kWho, ErrorCode::kSingular,
                 "loop 2 reaches a toggle (L4 and L5 collinear) within the L3 swing");
  }
}

BattenPose BattenLinkage::solve(double crank_rad) const {
  const Eigen::Vector2d a(d_.l1_m * std::cos(crank_rad), d_.l1_m * std::sin(crank_rad));
  const Eigen::Vector2d o3 = rocker_pivot(d_);
  const Eigen::Vector2d p = batten_pivot(d_);
  const Eigen::Vector2d b =
      detail::rocker_pin(o3, d_.l3_m, a, d_.l2_m, branch_.loop1 == LoopSide::kRight).point;
  const Eigen::Vector2d dd =
      detail::circle_intersection_valid(b, d_.l4_m, p, d_.l5_m, branch_.loop2 == LoopSide::kLeft);
  BattenPose x{};
  x.gamma2_rad = std::atan2(b.x() - a.x(), b.y() - a.y());  // B - A = L2 (sin γ2, cos γ2)
  x.gamma3_rad = std::atan2(b.y() - o3.y(), b.x() - o3.x());
  x.gamma4_rad = std::atan2(b.y() - dd.y(), b.x() - dd.x());
  x.psi_rad = wrap_two_pi(std::atan2(-(dd.x() - p.x()), dd.y() - p.y()));  // D - P = L5 (-sin ψ, cos ψ)
  return x;
}

Eigen::Vector4d BattenLinkage::residual(double crank_rad, const BattenPose& x) const {
  const BattenDims& d = d_;
  const double sp = std::sin(crank_rad), cp = std::cos(crank_rad);
  const double s2 = std::sin(x.gamma2_rad), c2 = std::cos(x.gamma2_rad);
  const double s3 = std::sin(x.gamma3_rad), c3 = std::cos(x.gamma3_rad);
  const double s4 = std::sin(x.gamma4_rad), c4 = std::cos(x.gamma4_rad);
  const double ss = std::sin(x.psi_rad), cs = std::cos(x.psi_rad);
  return {d.l1_m * cp + d.l2_m * s2 - d.l3_m * c3 + d.l7_m, d.l1_m * sp + d.l2_m * c2 - d.l3_m * s3 - d.l6_m,
          -d.l5_m * ss + d.l4_m * c4 - d.l3_m * c3 + d.l7_m + d.l9_m,
          d.l5_m * cs + d.l4_m * s4 - d.l3_m * s3 + d.l6_m + d.l8_m};
}

Eigen::Matrix4d BattenLinkage::jacobian(const BattenPose& x) const {
  const BattenDims& d = d_;
  const double s2 = std::sin(x.gamma2_rad), c2 = std::cos(x.gamma2_rad);
  const double s3 = std::sin(x.gamma3_rad), c3 = std::cos(x.gamma3_rad);
  const double s4 = std::sin(x.gamma4_rad), c4 = std::cos(x.gamma4_rad);
  const double ss = std::sin(x.psi_rad), cs = std::cos(x.psi_rad);
  Eigen::Matrix4d j;
  j << d.l2_m * c2, d.l3_m * s3, 0.0, 0.0,           //
      -d.l2_m * s2, -d.l3_m * c3, 0.0, 0.0,          //
      0.0, d.l3_m * s3, -d.l4_m * s4, -d.l5_m * cs,  //
      0.0, -d.l3_m * c3, d.l4_m * c4, -d.l5_m * ss;
  return j;
}

BattenBranch BattenLinkage::branch_of(const BattenPose& x) const {
  const double det1 = -std::cos(x.gamma2_rad + x.gamma3_rad);  // sign of -L2 L3 cos(γ2 + γ3)
  const double det2 = std::cos(x.gamma4_rad - x.psi_rad);      // sign of  L4 L5 cos(γ4 - ψ)
  return {det1 > 0.0 ? LoopSide::kLeft : LoopSide::kRight, det2 < 0.0 ? LoopSide::kLeft : LoopSide::kRight};
}

BattenRates BattenLinkage::rates(double crank_rad, const BattenPose& x, double crank_rate,
                                 double crank_accel) const {
  const BattenDims& d = d_;
  const Eigen::Matrix4d j = jacobian(x);
  const Eigen::Vector4d f_phi(-d.l1_m * std::sin(crank_rad), d.l1_m * std::cos(crank_rad), 0.0, 0.0);

  // J is block lower-triangular with 2×2 diagonal blocks that a validated linkage keeps regular:
  // two Cramer solves are exact and cheaper than a general factorisation.
  const auto solve = [&j](const Eigen::Vector4d& rhs) {
    const double det1 = j(0, 0) * j(1, 1) - j(0, 1) * j(1, 0);
    Eigen::Vector4d out;
    out(0) = (rhs(0) * j(1, 1) - j(0, 1) * rhs(1)) / det1;
    out(1) = (j(0, 0) * rhs(1) - rhs(0) * j(1, 0)) / det1;
    const double r2 = rhs(2) - j(2, 1) * out(1);
    const double r3 = rhs(3) - j(3, 1) * out(1);
    const double det2 = j(2, 2) * j(3, 3) - j(2, 3) * j(3, 2);
    out(2) = (r2 * j(3, 3) - j(2, 3) * r3) / det2;
    out(3) = (j(2, 2) * r3 - r2 * j(3, 2)) / det2;
    return out;
  };

  BattenRates r;
  r.dot = solve(-f_phi * crank_rate);

  // Every term of eqns (7) is L·sin(q) or L·cos(q); its second time derivative adds -term·q'².
  const double w = crank_rate, w2 = r.dot(0), w3 = r.dot(1), w4 = r.dot(2), wp = r.dot(3);
  const double sp = std::sin(crank_rad), cp = std::cos(crank_rad);
  const double s2 = std::sin(x.gamma2_rad), c2 = std::cos(x.gamma2_rad);
  const double s3 = std::sin(x.gamma3_rad), c3 = std::cos(x.gamma3_rad);
  const double s4 = std::sin(x.gamma4_rad), c4 = std::cos(x.gamma4_rad);
  const double ss = std::sin(x.psi_rad), cs = std::cos(x.psi_rad);
  const Eigen::Vector4d h(-(d.l1_m * cp * w * w + d.l2_m * s2 * w2 * w2 - d.l3_m * c3 * w3 * w3),
                          -(d.l1_m * sp * w * w + d.l2_m * c2 * w2 * w2 - d.l3_m * s3 * w3 * w3),
                          -(-d.l5_m * ss * wp * wp + d.l4_m * c4 * w4 * w4 - d.l3_m * c3 * w3 * w3),
                          -(d.l5_m * cs * wp * wp + d.l4_m * s4 * w4 * w4 - d.l3_m * s3 * w3 * w3));
  r.ddot = solve(-f_phi * crank_accel - h);
  return r;
}

}  // namespace loom::motion
