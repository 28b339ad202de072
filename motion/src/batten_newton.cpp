// Newton's method on 004's eqns (7), the paper's own solution route, hardened: a step limit keeps
// a poor guess from jumping across the circle, a singular Jacobian is an error, and after
// convergence the assembly branch is checked — Newton happily converges to the mirror assembly.
#include <algorithm>
#include <cmath>
#include <Eigen/LU>
#include <sstream>

#include "loom/motion/batten.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

// A full step larger than this (rad) is scaled down: far from the root the linearisation is poor
// and an unlimited step can land in the other assembly's basin.
constexpr double kMaxStepRad = 0.5;
// Smallest relative tolerance double precision can meet on eqns (7) (a few ulps of the largest link).
constexpr double kMinTolerance = 1e-15;

const char* side_name(LoopSide s) { return s == LoopSide::kLeft ? "left" : "right"; }

double principal(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

NewtonResult BattenLinkage::solve_newton(double crank_rad, const BattenPose& guess,
                                         const NewtonOptions& opt) const {
  if (!(opt.tolerance >= kMinTolerance) || !std::isfinite(opt.tolerance)) {
    std::ostringstream os;
    os << "batten Newton: tolerance = " << opt.tolerance << ": must be finite and >= " << kMinTolerance;
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  if (opt.max_iterations < 1) {
    throw MotionError(ErrorCode::kInvalidInput, "batten Newton: max_iterations = " +
                                                    std::to_string(opt.max_iterations) + ": must be >= 1");
  }
  const Eigen::Vector4d g = guess.vec();
  if (!g.allFinite() || !std::isfinite(crank_rad)) {
    throw MotionError(ErrorCode::kInvalidInput, "batten Newton: crank angle and guess must be finite");
  }

  const double stop = opt.tolerance * scale_m_;
  const double det_floor = 1e-12 * d_.l2_m * d_.l3_m * d_.l4_m * d_.l5_m;
  Eigen::Vector4d x = g;
  for (int it = 0; it <= opt.max_iterations; ++it) {
    const Eigen::Vector4d f = residual(crank_rad, BattenPose::from(x));
    const double r = f.cwiseAbs().maxCoeff();
    if (r <= stop) {
      NewtonResult out{};
      out.pose = {principal(x(0)), principal(x(1)), principal(x(2)), wrap_two_pi(x(3))};
      out.iterations = it;
      out.residual_m = r;
      const BattenBranch got = branch_of(out.pose);
      if (!(got == branch_)) {
        std::ostringstream os;
        os << "batten Newton converged to the wrong assembly branch at crank " << crank_rad
           << " rad: loop 1 " << side_name(got.loop1) << " / loop 2 " << side_name(got.loop2)
           << ", wanted " << side_name(branch_.loop1) << " / " << side_name(branch_.loop2);
        throw MotionError(ErrorCode::kWrongBranch, os.str());
      }
      return out;
    }
    if (it == opt.max_iterations) break;
    const Eigen::Matrix4d j = jacobian(BattenPose::from(x));
    if (!(std::abs(j.determinant()) > det_floor)) {
      std::ostringstream os;
      os << "batten Newton: singular Jacobian (a loop at toggle) at crank " << crank_rad
         << " rad after " << it << " steps";
      throw MotionError(ErrorCode::kSingular, os.str());
    }
    Eigen::Vector4d dx = j.partialPivLu().solve(-f);
    const double step = dx.cwiseAbs().maxCoeff();
    if (step > kMaxStepRad) dx *= kMaxStepRad / step;
    x += dx;
  }
  std::ostringstream os;
  os << "batten Newton: no convergence to " << opt.tolerance << " x largest link within "
     << opt.max_iterations << " steps at crank " << crank_rad << " rad";
  throw MotionError(ErrorCode::kNoConvergence, os.str());
}

}  // namespace loom::motion
