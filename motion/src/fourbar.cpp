// Four-bar analysis by triangle geometry rather than the Freudenstein half-angle form: the half-angle
// form divides by a coefficient that passes through zero inside a normal cycle, the triangle form only
// degenerates at true toggle/change-point poses, where we report it instead of returning NaN.
#include "loom/motion/fourbar.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <tuple>
#include <utility>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {
namespace {

void check_lengths(const FourBar& m) {
  const std::array<std::pair<const char*, double>, 4> links{
      {{"ground", m.ground}, {"crank", m.crank}, {"coupler", m.coupler}, {"rocker", m.rocker}}};
  for (const auto& [name, len] : links) {
    if (!(len > 0.0) || !std::isfinite(len)) {
      std::ostringstream os;
      os << "four-bar " << name << " length must be positive and finite, got " << len;
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
  }
}

// Relative tolerance for treating a cosine just outside [-1, 1] as rounding (poses at a limit).
constexpr double kCosSlack = 1e-12;

double clamp_cos(double c, const char* what, double theta2) {
  if (c > 1.0 + kCosSlack || c < -1.0 - kCosSlack) {
    std::ostringstream os;
    os << "four-bar cannot be assembled at crank angle " << deg(theta2) << " deg (" << what
       << " cosine " << c << ")";
    throw MotionError(ErrorCode::kNotAssemblable, os.str());
  }
  return std::clamp(c, -1.0, 1.0);
}

}  // namespace

const char* grashof_class_name(GrashofClass c) {
  switch (c) {
    case GrashofClass::kCrankRocker: return "crank-rocker";
    case GrashofClass::kDoubleCrank: return "double-crank";
    case GrashofClass::kRockerCrank: return "rocker-crank";
    case GrashofClass::kDoubleRocker: return "double-rocker";
    case GrashofClass::kTripleRocker: return "triple-rocker";
    case GrashofClass::kChangePoint: return "change-point";
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

FourBarPose solve(const FourBar& m, double theta2, Branch branch) {
  check_lengths(m);
  const double a = m.crank, b = m.coupler, c = m.rocker, d = m.ground;
  const double ax = a * std::cos(theta2), ay = a * std::sin(theta2);
  // Diagonal f from B0 to A; the triangle (B0, A, B) with sides f, b, c fixes the rocker.
  const double fx = ax - d, fy = ay;
  const double f = std::hypot(fx, fy);
  if (f <= 1e-15 * (a + d)) {
    throw MotionError(ErrorCode::kNotAssemblable, "four-bar crank pin coincides with the rocker pivot");
  }
  const double delta = std::atan2(fy, fx);  // direction B0 → A
  const double gamma = std::acos(clamp_cos((c * c + f * f - b * b) / (2.0 * c * f), "rocker", theta2));
  const double sigma = static_cast<double>(branch);
  FourBarPose p;
  p.theta2 = theta2;
  p.theta4 = delta + sigma * gamma;
  const double bx = d + c * std::cos(p.theta4), by = c * std::sin(p.theta4);
  p.theta3 = std::atan2(by - ay, bx - ax);

  // Velocity coefficients from the differentiated loop closure a·e^{iθ2} + b·e^{iθ3} = d + c·e^{iθ4}.
  const double s34 = std::sin(p.theta3 - p.theta4);
  if (std::abs(s34) < 1e-12) {
    std::ostringstream os;
    os << "four-bar at toggle (coupler and rocker colinear) at crank angle " << deg(theta2) << " deg";
    throw MotionError(ErrorCode::kSingular, os.str());
  }
  p.k3 = a * std::sin(p.theta4 - theta2) / (b * s34);
  p.k4 = a * std::sin(p.theta3 - theta2) / (c * s34);
  // Second derivatives: differentiate again (θ2'' = 0) and solve the same 2×2 system.
  //   -b sinθ3 k3' + c sinθ4 k4' = a cosθ2 + b k3² cosθ3 - c k4² cosθ4
  //    b cosθ3 k3' - c cosθ4 k4' = a sinθ2 + b k3² sinθ3 - c k4² sinθ4
  const double r1 = a * std::cos(theta2) + b * p.k3 * p.k3 * std::cos(p.theta3) -
                    c * p.k4 * p.k4 * std::cos(p.theta4);
  const double r2 = a * std::sin(theta2) + b * p.k3 * p.k3 * std::sin(p.theta3) -
                    c * p.k4 * p.k4 * std::sin(p.theta4);
  // Cramer's rule on [[-b s3, c s4], [b c3, -c c4]]; determinant = b c sin(θ3 - θ4).
  const double det = b * c * s34;
  const double s3 = std::sin(p.theta3), c3 = std::cos(p.theta3);
  const double s4 = std::sin(p.theta4), c4 = std::cos(p.theta4);
  p.k3p = (r1 * (-c * c4) - c * s4 * r2) / det;
  p.k4p = ((-b * s3) * r2 - b * c3 * r1) / det;
  // Transmission angle: between coupler and rocker at B.
  p.transmission = std::abs(wrap_pi(p.theta4 - p.theta3));
  return p;
}

DeadCentres dead_centres(const FourBar& m, Branch branch) {
  if (classify(m) != GrashofClass::kCrankRocker) {
    std::ostringstream os;
    os << "dead centres need a crank-rocker; these lengths make a " << grashof_class_name(classify(m));
    throw MotionError(ErrorCode::kNotCrank, os.str());
  }
  const double a = m.crank, b = m.coupler, c = m.rocker, d = m.ground;
  DeadCentres dc;
  // At a dead centre A0, A, B are colinear and |A0B| = b ± a. Solve the triangle (A0, B0, B) for the
  // crank direction, on the side of the chosen branch, then read the rocker from the full solve.
  const auto crank_at = [&](double reach, bool extended) {
    const double cos_at_a0 = clamp_cos((d * d + reach * reach - c * c) / (2.0 * d * reach), "dead-centre", 0);
    const double angle_b = std::acos(cos_at_a0);
    // Two mirror candidates (±angle_b); keep the one that lies on `branch`.
    for (const double sgn : {1.0, -1.0}) {
      const double dir_b = sgn * angle_b;  // direction A0 → B
      const double th2 = extended ? dir_b : dir_b + kPi;
      const FourBarPose pose = solve(m, th2, branch);
      const double bx = d + c * std::cos(pose.theta4), by = c * std::sin(pose.theta4);
      if (std::abs(wrap_pi(std::atan2(by, bx) - dir_b)) < 1e-6) {
        return std::pair{wrap_two_pi(th2), pose.theta4};
      }
    }
    throw MotionError(ErrorCode::kNotAssemblable, "four-bar dead centre not found on the requested branch");
  };
  std::tie(dc.crank_extended, dc.rocker_extended) = crank_at(b + a, true);
  std::tie(dc.crank_folded, dc.rocker_folded) = crank_at(b - a, false);
  dc.swing = std::abs(wrap_pi(dc.rocker_folded - dc.rocker_extended));
  dc.crank_rotation = wrap_two_pi(dc.crank_folded - dc.crank_extended);
  dc.time_ratio = dc.crank_rotation / (kTwoPi - dc.crank_rotation);
  // μ extremes occur where the diagonal f is shortest or longest: θ2 = 0 and θ2 = π.
  const auto mu_dev = [&](double f) {
    const double mu = std::acos(std::clamp((b * b + c * c - f * f) / (2.0 * b * c), -1.0, 1.0));
    return std::min(mu, kPi - mu);
  };
  dc.mu_min = std::min(mu_dev(d - a), mu_dev(d + a));
  return dc;
}

}  // namespace loom::motion
