// The planar motion of one rigid link at one instant, and what follows from it without any force
// analysis: point velocities/accelerations, kinetic energy, and the shaking force and moment a set of
// moving links transmits to the frame (seed 003 eqns 9–10). These are the independent truths the
// Newton–Euler solvers are checked against. Pure, allocation-free, RT-safe.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <span>

#include "loom/motion/mass_properties.hpp"

namespace loom::motion {

// A link frame's pose and its first and second time derivatives in the world frame.
struct BodyMotion {
  double angle_rad = 0.0, omega_rad_s = 0.0, alpha_rad_s2 = 0.0;
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d origin_vel_m_s = Eigen::Vector2d::Zero();
  Eigen::Vector2d origin_acc_m_s2 = Eigen::Vector2d::Zero();

  // RT-safe. A link-frame vector expressed in the world frame.
  Eigen::Vector2d rotate(const Eigen::Vector2d& local) const {
    const double c = std::cos(angle_rad), s = std::sin(angle_rad);
    return {c * local.x() - s * local.y(), s * local.x() + c * local.y()};
  }
  // RT-safe. World position, velocity and acceleration of a point fixed in the link frame:
  // p = o + Rρ, v = v_o + ω×Rρ, a = a_o + α×Rρ − ω²Rρ.
  Eigen::Vector2d point(const Eigen::Vector2d& local) const { return origin_m + rotate(local); }
  Eigen::Vector2d velocity(const Eigen::Vector2d& local) const {
    const Eigen::Vector2d r = rotate(local);
    return origin_vel_m_s + omega_rad_s * Eigen::Vector2d(-r.y(), r.x());
  }
  Eigen::Vector2d acceleration(const Eigen::Vector2d& local) const {
    const Eigen::Vector2d r = rotate(local);
    return origin_acc_m_s2 + alpha_rad_s2 * Eigen::Vector2d(-r.y(), r.x()) - omega_rad_s * omega_rad_s * r;
  }
};

// RT-safe. z-component of the planar cross product a × b.
inline double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// RT-safe. ½ m v_G² + ½ I_G ω².
double kinetic_energy(const PlanarInertia& body, const BodyMotion& m);

// RT-safe. −m g·r_G: potential energy in a uniform gravity field g (m/s², world frame).
double potential_energy(const PlanarInertia& body, const BodyMotion& m, const Eigen::Vector2d& gravity_m_s2);

// The dynamic load the moving links put on the frame (003's definition: the reaction of the inertia
// forces). force = Σ m a_G; moment about a frame point P = Σ (I_G α + (r_G − P) × m a_G), which
// includes the motor's reaction torque on its mounting. Static weight is not part of it.
struct ShakingLoad {
  Eigen::Vector2d force_n = Eigen::Vector2d::Zero();
  double moment_nm = 0.0;
};

// RT-safe. bodies[i] moves with motion[i]; the spans must have equal length (shorter one wins).
ShakingLoad shaking_load(std::span<const PlanarInertia> bodies, std::span<const BodyMotion> motion,
                         const Eigen::Vector2d& about_m);

// Root mean square over samples equally spaced in time: sqrt(Σ|f|²/δ), sqrt(Σn²/δ). (003 eqn 14
// prints (1/δ)·sqrt(Σ·), which is not an RMS and shrinks with the sample count; we use the RMS.)
struct ShakingRms {
  double force_n = 0.0;
  double moment_nm = 0.0;
};
// RT-safe (no allocation). Empty input gives zeros.
ShakingRms shaking_rms(std::span<const ShakingLoad> samples);

}  // namespace loom::motion
