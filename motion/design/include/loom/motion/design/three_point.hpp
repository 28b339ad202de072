// Three-precision-point synthesis of seed 001 (the knotting linkage): choose the lengths of a
// three-link chain A0 → O1 → O2 → P so that, with the first link fixed at angle θ0 and the last
// at a prescribed angle θ2_i, its end P passes through three given points. Configure-time only.
#pragma once

#include <array>
#include <vector>

namespace loom::motion {

// One precision point: where the chain's end must be, and the last link's angle there.
struct PrecisionPoint {
  double x = 0.0;
  double y = 0.0;
  double theta2_rad = 0.0;
};

// One real solution. The chain is a0·u(θ0) + a1·u(θ1_i) + a2·u(θ2_i) = P_i with u(θ) = (cos θ, sin θ).
// a0 and a2 keep their sign from the linear solve (negative: the link points along θ + π); a1 > 0.
struct ThreePointSolution {
  double lambda = 0.0;  // root of p·λ² + q·λ + r = 0, λ = 1/(a0·a2)
  double a0 = 0.0;
  double a1 = 0.0;
  double a2 = 0.0;
  std::array<double, 3> theta1_rad{};  // free link's angle at each precision point
  double closure_residual = 0.0;       // max_i |chain end − P_i|, in the points' length unit
};

struct ThreePointResult {
  std::vector<ThreePointSolution> solutions;  // every real solution (0, 1 or 2), λ descending
  int complex_roots = 0;                      // roots of the λ quadratic with no real value
  int rejected_roots = 0;                     // real roots without a finite chain (λ = 0, or a1² ≤ 0)
};

// configure-time only. The λ method of 001: the three loop equations are linear in
// P = (P1, 1/a2, 1/a0) once λ = 1/(a0·a2) is named, P = l + λ·M, and P2·P3 = λ gives the quadratic.
// Each solution is polished by Newton on the loop equations so closure ≤ 1e-12 of the largest link.
// Throws MotionError kInvalidInput for non-finite input and kSingular when the points do not
// determine the linear system (e.g. two identical precision points).
ThreePointResult three_point_synthesis(const std::array<PrecisionPoint, 3>& points, double theta0_rad);

}  // namespace loom::motion
