// Options of the Newton position solvers (four-bar and batten linkage): the papers' own numerical
// route, kept beside the closed forms so their agreement and their cost can be measured. Shared so
// that a tolerance means the same thing for every mechanism.
#pragma once

namespace loom::motion {

// Smallest relative tolerance double precision can meet on a loop-closure residual (a few ulps of
// the largest link).
inline constexpr double kMinNewtonTolerance = 1e-15;

struct NewtonOptions {
  double tolerance = 1e-13;  // stop when max|F_i| <= tolerance · (largest link); >= kMinNewtonTolerance
  int max_iterations = 50;
};

}  // namespace loom::motion
