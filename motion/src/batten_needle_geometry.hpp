// Small planar-geometry helpers shared by the batten (004) and needle (002) linkage solvers:
// two-circle intersection on a chosen side (one assembly branch, no acos/asin quadrant traps) and the
// range of cos over an arc (closed-form assemblability checks over a rocker swing). Internal header.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::motion::detail {

// RT-safe. The point at distance r0 from c0 and r1 from c1, on the left (left = true) or right of
// the directed line c0 -> c1, for a mechanism already validated to assemble. The height uses the
// product form ((r0+r1)² - d²)(d² - (r0-r1)²), which keeps its accuracy away from tangency; a product
// that rounds a hair below zero at (near-)tangency is clamped to the tangent point.
inline Eigen::Vector2d circle_intersection_valid(const Eigen::Vector2d& c0, double r0,
                                                 const Eigen::Vector2d& c1, double r1, bool left) {
  const Eigen::Vector2d dv = c1 - c0;
  const double d = dv.norm();
  const double prod = std::max(0.0, (r0 + r1 - d) * (r0 + r1 + d) * (d - (r0 - r1)) * (d + (r0 - r1)));
  const double h = std::sqrt(prod) / (2.0 * d);
  const double a = (d * d + r0 * r0 - r1 * r1) / (2.0 * d);
  const Eigen::Vector2d ex = dv / d;
  const Eigen::Vector2d ey(-ex.y(), ex.x());
  return c0 + a * ex + (left ? h : -h) * ey;
}

struct CosRange {
  double min;
  double max;
};

// RT-safe. Smallest and largest cos θ for θ in [lo, hi] (hi >= lo, hi - lo < 2π): the endpoints, plus
// ±1 wherever a multiple of π lies inside the arc.
inline CosRange cos_range(double lo, double hi) {
  CosRange r{std::min(std::cos(lo), std::cos(hi)), std::max(std::cos(lo), std::cos(hi))};
  const double first_even = std::ceil(lo / kTwoPi) * kTwoPi;              // cos = +1
  const double first_odd = std::ceil((lo - kPi) / kTwoPi) * kTwoPi + kPi;  // cos = -1
  if (first_even <= hi) r.max = 1.0;
  if (first_odd <= hi) r.min = -1.0;
  return r;
}

}  // namespace loom::motion::detail
