// Four-bar analysis by triangle geometry rather than the Freudenstein half-angle form: the half-angle
// form divides by a coefficient that passes through zero inside a normal cycle, the triangle form only
// degenerates at true toggle/change-point poses, where we report it instead of returning NaN. The
// triangle is closed by the shared two-circle helper (product-form height), as in every linkage here.
#include "loom/motion/fourbar.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <sstream>
#include <utility>

#include "checks.hpp"
#include "geometry.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "newton_solve.hpp"
#include "scale.hpp"

namespace loom::motion {
namespace {

// |sin μ| below this is a toggle: the coefficients' common denominator b·c·sin μ has no digits left.
constexpr double kToggleSine = 1e-12;

void check_lengths(const FourBar& m) {
  const std::array<std::pair<const char*, double>, 4> links{
      {{"ground", m.ground}, {"crank", m.crank}, {"coupler", m.coupler}, {"rocker", m.rocker}}};
  for (const auto& [name, len] : links) detail::require_positive_length("four-bar", name, len, "");
}

double largest_link(const FourBar& m) {
  return std::max({m.ground, m.crank, m.coupler, m.rocker});
}

std::string describe(const FourBar& m) {
  std::ostringstream os;
  os << "(ground " << m.ground << ", crank " << m.crank << ", coupler " << m.coupler << ", rocker "
     << m.rocker << ")";
  return os.str();
}

// Kinematic coefficients at a closed pose, from the differentiated loop closure
// a·e^{iθ2} + b·e^{iθ3} = d + c·e^{iθ4}. Throws kSingular at toggle.
FourBarPose with_coefficients(const FourBar& m, double theta2, double theta3, double theta4) {
  const double a = m.crank, b = m.coupler, c = m.rocker;
  FourBarPose p;
  p.theta2 = theta2;
  p.theta3 = theta3;
  p.theta4 = theta4;
  p.transmission = std::abs(wrap_pi(theta4 - theta3));
  const double s34 = std::sin(theta3 - theta4);
  if (std::abs(s34) < kToggleSine) {
    std::ostringstream os;
    os << "four-bar at toggle (coupler and rocker colinear) at crank angle " << deg(theta2)
       << " deg: velocity coefficients are unbounded " << describe(m);
    throw MotionError(ErrorCode::kSingular, os.str());
  }
  p.k3 = a * std::sin(theta4 - theta2) / (b * s34);
  p.k4 = a * std::sin(theta3 - theta2) / (c * s34);
  // Second derivatives: differentiate again (θ2'' = 0) and solve the same 2×2 system.
  //   -b sinθ3 k3' + c sinθ4 k4' = a cosθ2 + b k3² cosθ3 - c k4² cosθ4
  //    b cosθ3 k3' - c cosθ4 k4' = a sinθ2 + b k3² sinθ3 - c k4² sinθ4
  const double s3 = std::sin(theta3), c3 = std::cos(theta3);
  const double s4 = std::sin(theta4), c4 = std::cos(theta4);
  const double r1 = a * std::cos(theta2) + b * p.k3 * p.k3 * c3 - c * p.k4 * p.k4 * c4;
  const double r2 = a * std::sin(theta2) + b * p.k3 * p.k3 * s3 - c * p.k4 * p.k4 * s4;
  // Cramer's rule on [[-b s3, c s4], [b c3, -c c4]]; determinant = b c sin(θ3 - θ4).
  const double det = b * c * s34;
  p.k3p = (r1 * (-c * c4) - c * s4 * r2) / det;
  p.k4p = ((-b * s3) * r2 - b * c3 * r1) / det;
  return p;
}

}  // namespace

const char* grashof_class_name(GrashofClass c) {
  switch (c) {
    case GrashofClass::kCrankRocker:
      return "crank-rocker";
    case GrashofClass::kDoubleCrank:
      return "double-crank";
    case GrashofClass::kRockerCrank:
      return "rocker-crank";
    case GrashofClass::kDoubleRocker:
      return "double-rocker";
    case GrashofClass::kTripleRocker:
      return "triple-rocker";
    case GrashofClass::kChangePoint:
      return "change-point";
  }
  return "?";
}

GrashofClass classify(const FourBar& m) {
  check_lengths(m);
  std::array<double, 4> l{m.ground, m.crank, m.coupler, m.rocker};
  std::sort(l.begin(), l.end());
  const double s_plus_l = l[0] + l[3];
  const double p_plus_q = l[1] + l[2];
  // Equality within rounding of the largest link: a change-point linkage, which can fold flat.
  if (std::abs(s_plus_l - p_plus_q) <= 1e-12 * l[3]) return GrashofClass::kChangePoint;
  if (s_plus_l > p_plus_q) return GrashofClass::kTripleRocker;
  const double shortest = l[0];
  if (m.crank == shortest) return GrashofClass::kCrankRocker;
  if (m.ground == shortest) return GrashofClass::kDoubleCrank;
  if (m.rocker == shortest) return GrashofClass::kRockerCrank;
  return GrashofClass::kDoubleRocker;
}

// The linkage in units of a power of two near its largest link (scale.hpp): angles, coefficients and
// the relative tolerances are unchanged, and no square of a length can overflow at 1e150 or vanish at
// 1e-150.
static FourBar unit_scaled(const FourBar& m) {
  const double L = detail::length_scale(largest_link(m));
  return FourBar{m.ground / L, m.crank / L, m.coupler / L, m.rocker / L};
}

FourBarPosition solve_position(const FourBar& given, double theta2, Branch branch) {
  check_lengths(given);
  const FourBar m = unit_scaled(given);
  if (!std::isfinite(theta2)) {
    throw MotionError(ErrorCode::kInvalidInput, "four-bar: crank angle must be finite");
  }
  const double a = m.crank, b = m.coupler, c = m.rocker, d = m.ground;
  const double tol = 1e-12 * largest_link(m);
  const Eigen::Vector2d crank_pin(a * std::cos(theta2), a * std::sin(theta2));
  const Eigen::Vector2d b0(d, 0.0);
  if ((crank_pin - b0).norm() <= 1e-15 * (a + d)) {
    // A on B0: any rocker angle closes the loop when b = c, none otherwise.
    std::ostringstream os;
    os << "four-bar crank pin coincides with the rocker pivot at crank angle " << deg(theta2) << " deg "
       << describe(given);
    throw MotionError(std::abs(b - c) <= tol ? ErrorCode::kSingular : ErrorCode::kNotAssemblable, os.str());
  }
  // The triangle (B0, A, B) with sides |B0A|, b, c fixes the rocker on the branch's side of B0 → A.
  const detail::CircleIntersection pin =
      detail::rocker_pin_standard(d, a, b, c, theta2, branch == Branch::kPositive);
  if (pin.margin < -tol) {
    std::ostringstream os;
    os << "four-bar cannot be assembled at crank angle " << deg(theta2) << " deg: coupler and rocker miss "
       << "closing the loop by " << -pin.margin * (largest_link(given) / largest_link(m)) << " "
       << describe(given);
    throw MotionError(ErrorCode::kNotAssemblable, os.str());
  }
  FourBarPosition p;
  p.theta2 = theta2;
  p.theta4 = std::atan2(pin.point.y(), pin.point.x() - d);
  p.theta3 = std::atan2(pin.point.y() - crank_pin.y(), pin.point.x() - crank_pin.x());
  p.transmission = std::abs(wrap_pi(p.theta4 - p.theta3));
  // A flat triangle: the side (branch) is not resolved there and the rates are not finite.
  p.at_toggle = pin.clamped || std::abs(std::sin(p.transmission)) < kToggleSine;
  return p;
}

FourBarPose solve(const FourBar& given, double theta2, Branch branch) {
  const FourBarPosition p = solve_position(given, theta2, branch);
  const FourBar m = unit_scaled(given);
  if (p.at_toggle) {
    std::ostringstream os;
    os << "four-bar at toggle (coupler and rocker colinear within rounding) at crank angle " << deg(theta2)
       << " deg: velocity coefficients are unbounded " << describe(given);
    throw MotionError(ErrorCode::kSingular, os.str());
  }
  return with_coefficients(m, theta2, p.theta3, p.theta4);
}

Branch branch_of(double theta3, double theta4) {
  return std::sin(theta3 - theta4) > 0.0 ? Branch::kPositive : Branch::kNegative;
}

PointCoefficients point_coefficients(const FourBar& m, const FourBarPose& pose, FourBarLink link,
                                     const Eigen::Vector2d& local) {
  switch (link) {
    case FourBarLink::kCrank:
      return point_on_link(PointCoefficients{}, pose.theta2, 1.0, 0.0, local);
    case FourBarLink::kCoupler: {
      const Eigen::Vector2d pin(m.crank * std::cos(pose.theta2), m.crank * std::sin(pose.theta2));
      const PointCoefficients origin{pin, Eigen::Vector2d(-pin.y(), pin.x()), -pin};
      return point_on_link(origin, pose.theta3, pose.k3, pose.k3p, local);
    }
    case FourBarLink::kRocker:
      return point_on_link(
          PointCoefficients{Eigen::Vector2d(m.ground, 0.0), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()},
          pose.theta4, pose.k4, pose.k4p, local);
  }
  return {};
}

TransmissionRange transmission_range(const FourBar& given) {
  const GrashofClass cls = classify(given);
  const FourBar m = unit_scaled(given);
  if (cls != GrashofClass::kCrankRocker && cls != GrashofClass::kDoubleCrank) {
    std::ostringstream os;
    os << "transmission angle over a turn needs a crank that turns fully; these lengths make a "
       << grashof_class_name(cls) << " " << describe(given);
    throw MotionError(ErrorCode::kNotCrank, os.str());
  }
  TransmissionRange r;
  r.mu_min = detail::triangle_angle(std::abs(m.ground - m.crank), m.coupler, m.rocker);
  r.mu_max = detail::triangle_angle(m.ground + m.crank, m.coupler, m.rocker);
  r.worst_deviation_from_right = std::max(0.5 * kPi - r.mu_min, r.mu_max - 0.5 * kPi);
  r.min_abs_sin_mu = std::min(std::sin(r.mu_min), std::sin(r.mu_max));
  r.near_toggle = r.min_abs_sin_mu < kNearToggleSine;
  return r;
}

DeadCentres dead_centres(const FourBar& given, Branch branch) {
  const GrashofClass cls = classify(given);
  const FourBar m = unit_scaled(given);
  if (cls != GrashofClass::kCrankRocker) {
    std::ostringstream os;
    os << "dead centres need a crank-rocker; these lengths make a " << grashof_class_name(cls) << " "
       << describe(given);
    throw MotionError(ErrorCode::kNotCrank, os.str());
  }
  // At a dead centre A0, A, B are colinear and |A0B| = b ± a: one circle intersection each.
  const Eigen::Vector2d a0(0.0, 0.0), b0(m.ground, 0.0);
  const detail::DeadCentrePins pins =
      detail::dead_centre_pins(a0, b0, m.crank, m.coupler, m.rocker, branch == Branch::kPositive);
  DeadCentres dc;
  dc.crank_extended = wrap_two_pi(std::atan2(pins.extended.y(), pins.extended.x()));
  dc.crank_folded = wrap_two_pi(std::atan2(pins.folded.y(), pins.folded.x()) + kPi);
  dc.rocker_extended = std::atan2(pins.extended.y(), pins.extended.x() - m.ground);
  dc.rocker_folded = std::atan2(pins.folded.y(), pins.folded.x() - m.ground);
  dc.swing = std::abs(wrap_pi(dc.rocker_folded - dc.rocker_extended));
  dc.crank_rotation = wrap_two_pi(dc.crank_folded - dc.crank_extended);
  dc.time_ratio = dc.crank_rotation / (kTwoPi - dc.crank_rotation);
  dc.mu_min = 0.5 * kPi - transmission_range(m).worst_deviation_from_right;
  return dc;
}

std::vector<FourBarPose> fourbar_sweep(const FourBar& m, Branch branch, int samples, double theta2_start) {
  std::vector<FourBarPose> out;
  out.reserve(static_cast<std::size_t>(std::max(samples, 0)));
  fourbar_sweep(m, branch, samples, theta2_start, [&](const FourBarPose& p) { out.push_back(p); });
  return out;
}

void fourbar_sweep(const FourBar& m, Branch branch, int samples, double theta2_start,
                   const std::function<void(const FourBarPose&)>& sink) {
  detail::require_samples("four-bar sweep", samples);
  detail::require_finite("four-bar sweep", "theta2_start", theta2_start, " rad");
  const GrashofClass cls = classify(m);
  if (cls == GrashofClass::kChangePoint) {
    std::ostringstream os;
    os << "four-bar sweep: change-point linkage " << describe(m)
       << ": both branches meet where it folds flat, so the motion beyond is not determined";
    throw MotionError(ErrorCode::kSingular, os.str());
  }
  if (cls != GrashofClass::kCrankRocker && cls != GrashofClass::kDoubleCrank) {
    std::ostringstream os;
    os << "four-bar sweep: the crank cannot turn fully in a " << grashof_class_name(cls) << " "
       << describe(m);
    throw MotionError(ErrorCode::kNotCrank, os.str());
  }
  FourBarPose prev{};
  for (int i = 0; i < samples; ++i) {
    FourBarPose p =
        solve(m, theta2_start + kTwoPi * static_cast<double>(i) / static_cast<double>(samples), branch);
    if (i > 0) {
      p.theta3 = prev.theta3 + wrap_pi(p.theta3 - prev.theta3);
      p.theta4 = prev.theta4 + wrap_pi(p.theta4 - prev.theta4);
    }
    sink(p);
    prev = p;
  }
}

ReachableSweep fourbar_sweep_reachable(const FourBar& m, Branch branch, int samples, double theta2_start,
                                       const std::function<void(int, const FourBarPose&)>& sink) {
  detail::require_samples("four-bar sweep", samples);
  detail::require_finite("four-bar sweep", "theta2_start", theta2_start, " rad");
  check_lengths(m);
  if (classify(m) == GrashofClass::kChangePoint) {
    std::ostringstream os;
    os << "four-bar sweep: change-point linkage " << describe(m)
       << ": both branches meet where it folds flat, so the motion beyond is not determined";
    throw MotionError(ErrorCode::kSingular, os.str());
  }
  ReachableSweep cover;
  FourBarPose prev{};
  bool have_prev = false;
  for (int i = 0; i < samples; ++i) {
    const double theta2 = theta2_start + kTwoPi * static_cast<double>(i) / static_cast<double>(samples);
    const FourBarPosition pos = [&]() -> FourBarPosition {
      try {
        return solve_position(m, theta2, branch);
      } catch (const MotionError& e) {
        if (e.code() != ErrorCode::kNotAssemblable && e.code() != ErrorCode::kSingular) throw;
        FourBarPosition none;
        none.at_toggle = e.code() == ErrorCode::kSingular;
        none.theta2 = NAN;  // marks "did not close"
        return none;
      }
    }();
    if (std::isnan(pos.theta2) || pos.at_toggle) {
      ++(pos.at_toggle ? cover.at_toggle : cover.unreachable);
      have_prev = false;
      continue;
    }
    FourBarPose p = solve(m, theta2, branch);
    if (have_prev) {
      p.theta3 = prev.theta3 + wrap_pi(p.theta3 - prev.theta3);
      p.theta4 = prev.theta4 + wrap_pi(p.theta4 - prev.theta4);
    }
    sink(i, p);
    prev = p;
    have_prev = true;
    ++cover.solved;
  }
  return cover;
}

FourBarNewtonResult solve_newton(const FourBar& m, double theta2, Branch branch, double theta3_guess,
                                 double theta4_guess, const NewtonOptions& opt) {
  check_lengths(m);
  const double a = m.crank, b = m.coupler, c = m.rocker, d = m.ground;
  const double ax = a * std::cos(theta2), ay = a * std::sin(theta2);
  const auto residual = [&](const Eigen::Vector2d& x) {
    return Eigen::Vector2d(ax + b * std::cos(x(0)) - d - c * std::cos(x(1)),
                           ay + b * std::sin(x(0)) - c * std::sin(x(1)));
  };
  const auto jacobian = [&](const Eigen::Vector2d& x) {
    Eigen::Matrix2d j;
    j << -b * std::sin(x(0)), c * std::sin(x(1)),  //
        b * std::cos(x(0)), -c * std::cos(x(1));
    return j;
  };
  const detail::NewtonOutcome<2> n =
      detail::newton_solve<2>("four-bar Newton", theta2, Eigen::Vector2d(theta3_guess, theta4_guess), opt,
                              largest_link(m), 1e-12 * b * c, residual, jacobian);
  const double theta3 = std::atan2(std::sin(n.x(0)), std::cos(n.x(0)));
  const double theta4 = std::atan2(std::sin(n.x(1)), std::cos(n.x(1)));
  if (branch_of(theta3, theta4) != branch) {
    std::ostringstream os;
    os << "four-bar Newton converged to the wrong assembly branch at crank angle " << deg(theta2) << " deg "
       << "(wanted " << (branch == Branch::kPositive ? "positive" : "negative") << ")";
    throw MotionError(ErrorCode::kWrongBranch, os.str());
  }
  return {with_coefficients(m, theta2, theta3, theta4), n.iterations, n.residual};
}

}  // namespace loom::motion
