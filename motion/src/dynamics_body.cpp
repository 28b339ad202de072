// Kinetic/potential energy and shaking load of moving links, straight from their motion. Kept apart
// from the force solvers on purpose: the tests compare the two.
#include "loom/motion/dynamics_body.hpp"

#include <algorithm>
#include <cmath>

namespace loom::motion {

double kinetic_energy(const PlanarInertia& body, const BodyMotion& m) {
  const Eigen::Vector2d v = m.velocity(body.centre_m);
  return 0.5 * body.mass_kg * v.squaredNorm() + 0.5 * body.inertia_kg_m2 * m.omega_rad_s * m.omega_rad_s;
}

double potential_energy(const PlanarInertia& body, const BodyMotion& m, const Eigen::Vector2d& gravity_m_s2) {
  return -body.mass_kg * gravity_m_s2.dot(m.point(body.centre_m));
}

ShakingLoad shaking_load(std::span<const PlanarInertia> bodies, std::span<const BodyMotion> motion,
                         const Eigen::Vector2d& about_m) {
  ShakingLoad s;
  const std::size_t n = std::min(bodies.size(), motion.size());
  for (std::size_t i = 0; i < n; ++i) {
    const PlanarInertia& b = bodies[i];
    const BodyMotion& m = motion[i];
    const Eigen::Vector2d ma = b.mass_kg * m.acceleration(b.centre_m);
    s.force_n += ma;
    s.moment_nm += b.inertia_kg_m2 * m.alpha_rad_s2 + cross2(m.point(b.centre_m) - about_m, ma);
  }
  return s;
}

ShakingRms shaking_rms(std::span<const ShakingLoad> samples) {
  ShakingRms r;
  if (samples.empty()) return r;
  double f2 = 0.0, n2 = 0.0;
  for (const ShakingLoad& s : samples) {
    f2 += s.force_n.squaredNorm();
    n2 += s.moment_nm * s.moment_nm;
  }
  const double inv = 1.0 / static_cast<double>(samples.size());
  r.force_n = std::sqrt(f2 * inv);
  r.moment_nm = std::sqrt(n2 * inv);
  return r;
}

}  // namespace loom::motion
