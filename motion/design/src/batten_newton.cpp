// Newton's method on 004's eqns (7), the paper's own solution route, through the shared hardened
// solver (step limit, singular Jacobian, budget); after convergence the assembly branch is checked
// here, because Newton happily converges to the mirror assembly.
#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/batten.hpp"
#include "loom/motion/errors.hpp"
#include "newton_solve.hpp"

namespace loom::motion {

namespace {

const char* side_name(LoopSide s) {
  return s == LoopSide::kLeft ? "left" : "right";
}

double principal(double a) {
  return std::atan2(std::sin(a), std::cos(a));
}

}  // namespace

NewtonResult BattenLinkage::solve_newton(double crank_rad, const BattenPose& guess,
                                         const NewtonOptions& opt) const {
  const double det_floor = 1e-12 * d_.l2_m * d_.l3_m * d_.l4_m * d_.l5_m;
  const detail::NewtonOutcome<4> n = detail::newton_solve<4>(
      "batten Newton", crank_rad, guess.vec(), opt, scale_m_, det_floor,
      [&](const Eigen::Vector4d& x) { return residual(crank_rad, BattenPose::from(x)); },
      [&](const Eigen::Vector4d& x) { return jacobian(BattenPose::from(x)); });
  NewtonResult out{};
  out.pose = {principal(n.x(0)), principal(n.x(1)), principal(n.x(2)), wrap_two_pi(n.x(3))};
  out.iterations = n.iterations;
  out.residual_m = n.residual;
  const BattenBranch got = branch_of(out.pose);
  if (!(got == branch_)) {
    std::ostringstream os;
    os << "batten Newton converged to the wrong assembly branch at crank " << crank_rad << " rad: loop 1 "
       << side_name(got.loop1) << " / loop 2 " << side_name(got.loop2) << ", wanted "
       << side_name(branch_.loop1) << " / " << side_name(branch_.loop2);
    throw MotionError(ErrorCode::kWrongBranch, os.str());
  }
  return out;
}

}  // namespace loom::motion
