// The geared batten drive of seed 004: driving pinion φ1 -> elliptic gear -> crank φ2 = φ02 + φ2(φ1)
// (eqn 8) -> linkage eqns (7) -> batten ψ. Chain rule: φ2' = (dφ2/dφ1)·ω1 and
// φ2'' = (d²φ2/dφ1²)·ω1² + (dφ2/dφ1)·α1 feed the linkage's exact rates.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "checks.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/batten.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

struct CrankMotion {
  double angle, rate, accel;
};

CrankMotion crank_motion(const EllipticGearPair& gear, double phi02, double phi1, double w1, double a1) {
  const GearPhase g = gear.phase(phi1);
  return {phi02 + g.phi2_rad, g.dphi2 * w1, g.d2phi2 * w1 * w1 + g.dphi2 * a1};
}

BattenSample assemble(const BattenLinkage& linkage, double phi1, const CrankMotion& c, const BattenPose& x) {
  BattenSample s{};
  s.phi1_rad = phi1;
  s.phi2_rad = c.angle;
  s.pose = x;
  s.rates = linkage.rates(c.angle, x, c.rate, c.accel);
  s.psi_rad = x.psi_rad;
  s.psi_dot_rad_s = s.rates.dot(3);
  s.psi_ddot_rad_s2 = s.rates.ddot(3);
  return s;
}

double unwrap(double prev, double now) {
  return prev + wrap_pi(now - prev);
}

}  // namespace

BattenDrive::BattenDrive(const EllipticGearPair& gear, const BattenLinkage& linkage, double phi02_rad)
    : gear_(gear), linkage_(linkage), phi02_rad_(phi02_rad) {
  if (!std::isfinite(phi02_rad_)) {
    std::ostringstream os;
    os << "batten drive: phi02 = " << phi02_rad_ << " rad: must be finite";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
}

BattenSample BattenDrive::evaluate(double phi1_rad, double omega1_rad_s, double alpha1_rad_s2) const {
  const CrankMotion c = crank_motion(gear_, phi02_rad_, phi1_rad, omega1_rad_s, alpha1_rad_s2);
  return assemble(linkage_, phi1_rad, c, linkage_.solve(c.angle));
}

BattenSample BattenDrive::evaluate_newton(double phi1_rad, double omega1_rad_s, const BattenPose& guess,
                                          const NewtonOptions& opt, int* iterations) const {
  const CrankMotion c = crank_motion(gear_, phi02_rad_, phi1_rad, omega1_rad_s, 0.0);
  const NewtonResult n = linkage_.solve_newton(c.angle, guess, opt);
  if (iterations != nullptr) *iterations = n.iterations;
  return assemble(linkage_, phi1_rad, c, n.pose);
}

std::vector<BattenSample> batten_sweep(const BattenDrive& drive, int samples, double omega1_rad_s,
                                       BattenSolver solver, const NewtonOptions& opt) {
  std::vector<BattenSample> out;
  out.reserve(static_cast<std::size_t>(std::max(samples, 0)));
  batten_sweep(
      drive, samples, omega1_rad_s, [&](const BattenSample& s) { out.push_back(s); }, solver, opt);
  return out;
}

void batten_sweep(const BattenDrive& drive, int samples, double omega1_rad_s,
                  const std::function<void(const BattenSample&)>& sink, BattenSolver solver,
                  const NewtonOptions& opt) {
  detail::require_samples("batten sweep", samples);
  detail::require_finite("batten sweep", "omega1", omega1_rad_s, " rad/s");
  BattenSample prev{};
  for (int i = 0; i < samples; ++i) {
    const double phi1 = kTwoPi * static_cast<double>(i) / static_cast<double>(samples);
    BattenSample s{};
    if (solver == BattenSolver::kClosedForm || i == 0) {
      s = drive.evaluate(phi1, omega1_rad_s);
      if (solver == BattenSolver::kNewton) {
        // The closed form only names the assembly; Newton still has to converge from it.
        s = drive.evaluate_newton(phi1, omega1_rad_s, s.pose, opt);
      }
    } else {
      s = drive.evaluate_newton(phi1, omega1_rad_s, prev.pose, opt);
    }
    if (i > 0) {
      const BattenPose& p = prev.pose;
      s.pose.gamma2_rad = unwrap(p.gamma2_rad, s.pose.gamma2_rad);
      s.pose.gamma3_rad = unwrap(p.gamma3_rad, s.pose.gamma3_rad);
      s.pose.gamma4_rad = unwrap(p.gamma4_rad, s.pose.gamma4_rad);
      s.pose.psi_rad = unwrap(p.psi_rad, s.pose.psi_rad);
      s.psi_rad = s.pose.psi_rad;
    }
    sink(s);
    prev = s;
  }
}

std::vector<BattenExtreme> batten_extremes(const BattenDrive& drive, int samples, double omega1_rad_s) {
  if (!(omega1_rad_s > 0.0) || !std::isfinite(omega1_rad_s)) {
    std::ostringstream os;
    os << "batten extremes: omega1 = " << omega1_rad_s << " rad/s: must be finite and > 0";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  const std::vector<BattenSample> sw = batten_sweep(drive, samples, omega1_rad_s);
  std::vector<BattenExtreme> out;
  for (std::size_t i = 0; i < sw.size(); ++i) {
    const std::size_t j = (i + 1) % sw.size();
    const double v0 = sw[i].psi_dot_rad_s;
    if ((v0 > 0.0) == (sw[j].psi_dot_rad_s > 0.0)) continue;
    double lo = sw[i].phi1_rad;
    double hi = j == 0 ? kTwoPi : sw[j].phi1_rad;
    const bool rising = v0 > 0.0;
    // Bisection until the bracket stops shrinking: ψ' is smooth and changes sign exactly once here.
    for (int it = 0; it < 200 && hi - lo > 0.0; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      if ((drive.evaluate(mid, omega1_rad_s).psi_dot_rad_s > 0.0) == rising) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    const double at = 0.5 * (lo + hi);
    const BattenSample s = drive.evaluate(at, omega1_rad_s);
    out.push_back({wrap_two_pi(at), s.psi_rad, s.psi_ddot_rad_s2, rising});
  }
  return out;
}

}  // namespace loom::motion
