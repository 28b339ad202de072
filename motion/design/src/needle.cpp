// Needle six-bar of seed 002, derived afresh from its loop equations (eqns 1, 14, 15). Positions are
// two-circle intersections on a named side instead of 002's asin (eqn 9 cannot return the
// second-quadrant coupler angle Table 1 actually has) and acos; rates come from differentiating the
// loops. Validation runs once, in closed form, so that evaluate() is branch-safe for every θ1.
#include "loom/motion/design/needle.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "checks.hpp"
#include "geometry.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

constexpr const char* kWho = "needle six-bar";

}  // namespace

const char* needle_rocker_side_name(NeedleRockerSide s) {
  return s == NeedleRockerSide::kPinAwayFromNeedle ? "away" : "toward";
}

const char* needle_rod_side_name(NeedleRodSide s) {
  return s == NeedleRodSide::kHangingRod ? "hanging" : "standing";
}

NeedleDims needle_table1() {
  NeedleDims d{};
  d.l1_m = 0.015;
  d.l2_m = 0.138;
  d.l3_m = 0.115;
  d.l4_m = 0.125;
  d.l5_m = 0.120;
  d.l6_m = 0.440;
  d.x1_m = 0.070;
  d.x2_m = 0.100;
  d.h1_m = 0.155;
  d.beta1_rad = rad(168.0);
  return d;
}

NeedleLinkage::NeedleLinkage(const NeedleDims& dims, NeedleBranch branch) : d_(dims), branch_(branch) {
  static constexpr const char* kLinks[6] = {"l1", "l2", "l3", "l4", "l5", "l6"};
  const double links[6] = {d_.l1_m, d_.l2_m, d_.l3_m, d_.l4_m, d_.l5_m, d_.l6_m};
  for (int i = 0; i < 6; ++i) detail::require_positive_length(kWho, kLinks[i], links[i]);
  detail::require_finite(kWho, "x1", d_.x1_m, " m");
  detail::require_finite(kWho, "h1", d_.h1_m, " m");
  detail::require_finite(kWho, "x2", d_.x2_m, " m");
  detail::require_finite(kWho, "beta1", d_.beta1_rad, " rad");

  // The crank-rocker O-A-B-C: l1 shorter than |OC| (so l3 rocks) and turning fully.
  const double g = std::hypot(d_.x1_m, d_.h1_m);
  const detail::CrankTurn turn = detail::crank_turn(g, d_.l1_m, d_.l2_m, d_.l3_m);
  if (d_.l1_m >= g || turn == detail::CrankTurn::kBlocked) {
    std::ostringstream os;
    os << "l1 = " << d_.l1_m << " m cannot turn fully: a crank-rocker needs l1 < |OC| = " << g
       << " m, |OC| - l1 > |l2 - l3| and |OC| + l1 < l2 + l3 (l2 = " << d_.l2_m << " m, l3 = " << d_.l3_m
       << " m)";
    detail::fail(kWho, ErrorCode::kNotCrank, os.str());
  }
  if (turn == detail::CrankTurn::kChangePoint) {
    detail::fail(kWho, ErrorCode::kSingular,
                 "change-point crank-rocker (|OC| ± l1 equals l2 ± l3): the "
                 "coupler and rocker fold flat once per turn");
  }

  // Rocker swing limits at the two dead centres.
  const bool left = branch_.rocker == NeedleRockerSide::kPinTowardNeedle;
  const Eigen::Vector2d origin(0.0, 0.0);
  const Eigen::Vector2d c(d_.x1_m, d_.h1_m);
  const detail::DeadCentrePins pins = detail::dead_centre_pins(origin, c, d_.l1_m, d_.l2_m, d_.l3_m, left);
  limits_.extended_rad = wrap_two_pi(std::atan2(pins.extended.y() - c.y(), pins.extended.x() - c.x()));
  limits_.folded_rad = wrap_two_pi(std::atan2(pins.folded.y() - c.y(), pins.folded.x() - c.x()));

  // The rocker swings through less than π, on the arc that contains any actual pose.
  const double ref = evaluate(0.0, 0.0).theta3_rad;
  const double da = wrap_pi(limits_.extended_rad - ref);
  const double db = wrap_pi(limits_.folded_rad - ref);
  const double shift = d_.beta1_rad - kTwoPi;
  const detail::CosRange cr =
      detail::cos_range(ref + std::min(da, db) + shift, ref + std::max(da, db) + shift);
  // Horizontal reach the rod must span: c5 = x2 - l4 cos θ4 over the swing; |c5| < l5 everywhere.
  const double reach = std::max(std::abs(d_.x2_m - d_.l4_m * cr.max), std::abs(d_.x2_m - d_.l4_m * cr.min));
  const double rod_tol = 1e-12 * std::max({d_.l4_m, d_.l5_m, std::abs(d_.x2_m)});
  if (reach > d_.l5_m + rod_tol) {
    std::ostringstream os;
    os << "l5 = " << d_.l5_m << " m cannot reach the needle line: over the rocker swing the "
       << "horizontal gap x2 - l4 cos θ4 reaches " << reach << " m (x2 = " << d_.x2_m
       << " m, l4 = " << d_.l4_m << " m, beta1 = " << deg(d_.beta1_rad) << " deg)";
    detail::fail(kWho, ErrorCode::kNotAssemblable, os.str());
  }
  if (reach >= d_.l5_m - rod_tol) {
    detail::fail(
        kWho, ErrorCode::kSingular,
        "the rod l5 lies horizontal (toggle) within the rocker swing: needle velocity would be unbounded");
  }
}

NeedleState NeedleLinkage::evaluate(double theta1_rad, double omega1_rad_s, double alpha1_rad_s2) const {
  const double l1 = d_.l1_m, l2 = d_.l2_m, l3 = d_.l3_m, l4 = d_.l4_m, l5 = d_.l5_m;
  NeedleState s{};
  s.theta1_rad = theta1_rad;
  s.omega1_rad_s = omega1_rad_s;
  s.alpha1_rad_s2 = alpha1_rad_s2;

  // ---- positions -------------------------------------------------------------------------------
  const Eigen::Vector2d a(l1 * std::cos(theta1_rad), l1 * std::sin(theta1_rad));
  const Eigen::Vector2d c(d_.x1_m, d_.h1_m);
  const Eigen::Vector2d b =
      detail::rocker_pin(c, l3, a, l2, branch_.rocker == NeedleRockerSide::kPinTowardNeedle).point;
  s.theta3_rad = wrap_two_pi(std::atan2(b.y() - c.y(), b.x() - c.x()));
  s.theta2_rad = std::atan2(b.y() - a.y(), b.x() - a.x());
  s.theta4_rad = s.theta3_rad + d_.beta1_rad - kTwoPi;
  const double c5 = d_.x2_m - l4 * std::cos(s.theta4_rad);  // = l5 cos θ5
  const double s5_abs = std::sqrt(std::max(0.0, (l5 - c5) * (l5 + c5)));
  s.theta5_rad = std::atan2(branch_.rod == NeedleRodSide::kStandingRod ? s5_abs : -s5_abs, c5);

  const double t1 = s.theta1_rad, t2 = s.theta2_rad, t3 = s.theta3_rad, t4 = s.theta4_rad, t5 = s.theta5_rad;
  const double w1 = omega1_rad_s, a1 = alpha1_rad_s2;

  // ---- velocities: d/dt of l1 e^{iθ1} + l2 e^{iθ2} - l3 e^{iθ3} = C, projected to kill one unknown
  s.omega2_rad_s = -l1 * w1 * std::sin(t1 - t3) / (l2 * std::sin(t2 - t3));
  s.omega3_rad_s = l1 * w1 * std::sin(t1 - t2) / (l3 * std::sin(t3 - t2));
  const double w2 = s.omega2_rad_s, w3 = s.omega3_rad_s;
  s.omega4_rad_s = w3;  // l3 and l4 are one rigid body
  const double w4 = w3;
  s.omega5_rad_s = -l4 * w4 * std::sin(t4) / (l5 * std::sin(t5));
  const double w5 = s.omega5_rad_s;

  // ---- accelerations (002 eqns 12-13 and 18, extended by the crank's own α1) -----------------
  s.alpha2_rad_s2 = (l3 * w3 * w3 - l1 * w1 * w1 * std::cos(t1 - t3) - l2 * w2 * w2 * std::cos(t2 - t3) -
                     l1 * a1 * std::sin(t1 - t3)) /
                    (l2 * std::sin(t2 - t3));
  s.alpha3_rad_s2 = (l2 * w2 * w2 + l1 * w1 * w1 * std::cos(t1 - t2) - l3 * w3 * w3 * std::cos(t3 - t2) +
                     l1 * a1 * std::sin(t1 - t2)) /
                    (l3 * std::sin(t3 - t2));
  s.alpha4_rad_s2 = s.alpha3_rad_s2;
  const double a4 = s.alpha4_rad_s2;
  s.alpha5_rad_s2 = -(l4 * a4 * std::sin(t4) + l4 * w4 * w4 * std::cos(t4) + l5 * w5 * w5 * std::cos(t5)) /
                    (l5 * std::sin(t5));
  const double a5 = s.alpha5_rad_s2;

  // ---- needle point F: l_CF' = l6 - l4 sin θ4 - l5 sin θ5 and its time derivatives -------------
  s.needle_m = d_.l6_m - l4 * std::sin(t4) - l5 * std::sin(t5);
  s.needle_v_m_s = -l4 * w4 * std::cos(t4) - l5 * w5 * std::cos(t5);
  s.needle_a_m_s2 = -l4 * a4 * std::cos(t4) + l4 * w4 * w4 * std::sin(t4) - l5 * a5 * std::cos(t5) +
                    l5 * w5 * w5 * std::sin(t5);
  return s;
}

double NeedleLinkage::closure_residual_m(const NeedleState& s) const {
  const double rx = d_.l1_m * std::cos(s.theta1_rad) + d_.l2_m * std::cos(s.theta2_rad) -
                    d_.l3_m * std::cos(s.theta3_rad) - d_.x1_m;
  const double ry = d_.l1_m * std::sin(s.theta1_rad) + d_.l2_m * std::sin(s.theta2_rad) -
                    d_.l3_m * std::sin(s.theta3_rad) - d_.h1_m;
  const double rod = d_.l4_m * std::cos(s.theta4_rad) + d_.l5_m * std::cos(s.theta5_rad) - d_.x2_m;
  const double bend = wrap_pi(s.theta4_rad - s.theta3_rad - d_.beta1_rad) * d_.l4_m;
  return std::max({std::abs(rx), std::abs(ry), std::abs(rod), std::abs(bend)});
}

std::vector<NeedleState> needle_sweep(const NeedleLinkage& linkage, int samples, double omega1_rad_s) {
  std::vector<NeedleState> out;
  out.reserve(static_cast<std::size_t>(std::max(samples, 0)));
  needle_sweep(linkage, samples, omega1_rad_s, [&](const NeedleState& s) { out.push_back(s); });
  return out;
}

void needle_sweep(const NeedleLinkage& linkage, int samples, double omega1_rad_s,
                  const std::function<void(const NeedleState&)>& sink) {
  detail::require_samples("needle sweep", samples);
  detail::require_finite("needle sweep", "omega1", omega1_rad_s, " rad/s");
  NeedleState p{};
  for (int i = 0; i < samples; ++i) {
    const double theta1 = kTwoPi * static_cast<double>(i) / static_cast<double>(samples);
    NeedleState s = linkage.evaluate(theta1, omega1_rad_s);
    if (i > 0) {
      s.theta2_rad = p.theta2_rad + wrap_pi(s.theta2_rad - p.theta2_rad);
      s.theta3_rad = p.theta3_rad + wrap_pi(s.theta3_rad - p.theta3_rad);
      s.theta4_rad = p.theta4_rad + wrap_pi(s.theta4_rad - p.theta4_rad);
      s.theta5_rad = p.theta5_rad + wrap_pi(s.theta5_rad - p.theta5_rad);
    }
    sink(s);
    p = s;
  }
}

}  // namespace loom::motion
