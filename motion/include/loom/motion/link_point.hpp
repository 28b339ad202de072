// A point fixed on a moving link of a one-degree-of-freedom linkage, as kinematic coefficients: its
// position and its first and second derivatives with respect to the input angle. Coefficients do
// not depend on the speed law, so one evaluation serves every crank speed; point_motion() turns them
// into velocity and acceleration. Pure, allocation-free, RT-safe.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace loom::motion {

struct PointCoefficients {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // P
  Eigen::Vector2d d1 = Eigen::Vector2d::Zero();        // dP/dθ (θ: the input angle)
  Eigen::Vector2d d2 = Eigen::Vector2d::Zero();        // d²P/dθ²
};

struct PointMotion {
  Eigen::Vector2d position, velocity, acceleration;
};

// RT-safe. Chain rule for an input turning at ω with acceleration α: v = P'ω, a = P'α + P''ω².
inline PointMotion point_motion(const PointCoefficients& c, double omega, double alpha) {
  return {c.position, c.d1 * omega, c.d1 * alpha + c.d2 * (omega * omega)};
}

// RT-safe. The point `local` (x along the link's reference line, y 90° counter-clockwise from it) of a
// link whose frame origin has coefficients `origin` and whose angle is `angle` with dangle/dθ = k and
// d²angle/dθ² = kp: P = O + R·local, P' = O' + k·J·R·local, P'' = O'' + kp·J·R·local − k²·R·local.
inline PointCoefficients point_on_link(const PointCoefficients& origin, double angle, double k, double kp,
                                       const Eigen::Vector2d& local) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Eigen::Vector2d r(c * local.x() - s * local.y(), s * local.x() + c * local.y());
  const Eigen::Vector2d jr(-r.y(), r.x());
  return {origin.position + r, origin.d1 + k * jr, origin.d2 + kp * jr - (k * k) * r};
}

}  // namespace loom::motion
