// Newton's method on a square loop-closure system in link angles, hardened the same way for every
// mechanism: options checked, a step limit so a poor guess cannot jump into the other assembly's
// basin, a singular Jacobian reported as such, and a typed error when the budget runs out. The
// assembly-branch check after convergence belongs to the caller, who knows its branches. Internal.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <sstream>
#include <string>

#include "loom/motion/errors.hpp"
#include "loom/motion/newton.hpp"

namespace loom::motion::detail {

// A full step larger than this (rad) is scaled down: far from the root the linearisation is poor
// and an unlimited step can land in the other assembly's basin.
inline constexpr double kMaxNewtonStepRad = 0.5;

template <int N>
struct NewtonOutcome {
  Eigen::Matrix<double, N, 1> x;
  int iterations;   // steps taken (0 when the guess already met the tolerance)
  double residual;  // max|F_i| at x, in the residual's length unit
};

// configure-time only. Solves F(x) = 0 from `x` until max|F_i| <= opt.tolerance · scale. `who`
// names the solver in messages ("four-bar Newton"), `input_rad` the driving angle. Throws
// MotionError kInvalidInput (bad options, non-finite guess or input), kSingular (|det J| <=
// det_floor on the way), kNoConvergence (budget spent).
template <int N, class Residual, class Jacobian>
NewtonOutcome<N> newton_solve(const char* who, double input_rad, Eigen::Matrix<double, N, 1> x,
                              const NewtonOptions& opt, double scale, double det_floor,
                              const Residual& residual, const Jacobian& jacobian) {
  if (!(opt.tolerance >= kMinNewtonTolerance) || !std::isfinite(opt.tolerance)) {
    std::ostringstream os;
    os << who << ": tolerance = " << opt.tolerance << ": must be finite and >= " << kMinNewtonTolerance;
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  if (opt.max_iterations < 1) {
    throw MotionError(ErrorCode::kInvalidInput, std::string(who) + ": max_iterations = " +
                                                    std::to_string(opt.max_iterations) + ": must be >= 1");
  }
  if (!x.allFinite() || !std::isfinite(input_rad)) {
    throw MotionError(ErrorCode::kInvalidInput, std::string(who) + ": input angle and guess must be finite");
  }
  const double stop = opt.tolerance * scale;
  for (int it = 0; it <= opt.max_iterations; ++it) {
    const Eigen::Matrix<double, N, 1> f = residual(x);
    const double r = f.cwiseAbs().maxCoeff();
    if (r <= stop) return {x, it, r};
    if (it == opt.max_iterations) break;
    const Eigen::Matrix<double, N, N> j = jacobian(x);
    if (!(std::abs(j.determinant()) > det_floor)) {
      std::ostringstream os;
      os << who << ": singular Jacobian (a loop at toggle) at input " << input_rad << " rad after " << it
         << " steps";
      throw MotionError(ErrorCode::kSingular, os.str());
    }
    Eigen::Matrix<double, N, 1> dx = j.partialPivLu().solve(-f);
    const double step = dx.cwiseAbs().maxCoeff();
    if (step > kMaxNewtonStepRad) dx *= kMaxNewtonStepRad / step;
    x += dx;
  }
  std::ostringstream os;
  os << who << ": no convergence to " << opt.tolerance << " x largest link within " << opt.max_iterations
     << " steps at input " << input_rad << " rad";
  throw MotionError(ErrorCode::kNoConvergence, os.str());
}

}  // namespace loom::motion::detail
