// Three-point equimomental systems (003 eqns 1–4). The closed form replaces a 3×3 solve: with the
// points 120° apart the centre condition decouples into cosine weights, which also shows when a mass
// turns negative: when the centre's projection on that point's direction is below −l/2.
#include "loom/motion/design/equimomental.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

std::array<PointMass, 3> equimomental_points(double m1, double m2, double m3, double l, double offset) {
  const std::array<double, 3> m{m1, m2, m3};
  std::array<PointMass, 3> p;
  for (int j = 0; j < 3; ++j) {
    const double th = offset + kTwoPi * j / 3.0;
    p[j] = {m[j], l * Eigen::Vector2d(std::cos(th), std::sin(th))};
  }
  return p;
}

EquimomentalSystem equimomental_three_origin(double m, const Eigen::Vector2d& centre, double inertia_origin,
                                             double offset) {
  if (!(m > 0.0) || !std::isfinite(m) || !centre.allFinite() || !(inertia_origin >= 0.0) ||
      !std::isfinite(inertia_origin) || !std::isfinite(offset)) {
    std::ostringstream os;
    os << "equimomental system: link mass " << m << " kg, inertia about the link origin " << inertia_origin
       << " kg m^2, angle offset " << offset << " rad: mass must be > 0, inertia >= 0, all finite";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  EquimomentalSystem s;
  s.radius_m = std::sqrt(inertia_origin / m);
  const double l = s.radius_m;
  // m_j = (m/3)(1 + 2 (c·u_j)/l), u_j the unit vector of point j; l > 0 whenever the body has
  // inertia or an off-origin centre. A point body at the origin (l = 0) takes equal thirds.
  std::array<double, 3> mj{m / 3.0, m / 3.0, m / 3.0};
  if (l > 0.0) {
    for (int j = 0; j < 3; ++j) {
      const double th = offset + kTwoPi * j / 3.0;
      const Eigen::Vector2d u(std::cos(th), std::sin(th));
      mj[j] = m / 3.0 * (1.0 + 2.0 * centre.dot(u) / l);
    }
  }
  s.points = equimomental_points(mj[0], mj[1], mj[2], l, offset);
  s.all_positive = mj[0] >= 0.0 && mj[1] >= 0.0 && mj[2] >= 0.0;
  return s;
}

EquimomentalSystem equimomental_three(const PlanarInertia& body, double offset) {
  if (!(body.mass_kg > 0.0) || !std::isfinite(body.mass_kg) || !body.centre_m.allFinite() ||
      !(body.inertia_kg_m2 >= 0.0) || !std::isfinite(body.inertia_kg_m2) || !std::isfinite(offset)) {
    std::ostringstream os;
    os << "equimomental system: link mass " << body.mass_kg << " kg, inertia " << body.inertia_kg_m2
       << " kg m^2, angle offset " << offset << " rad: mass must be > 0, all finite";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  return equimomental_three_origin(body.mass_kg, body.centre_m, body.inertia_about(Eigen::Vector2d::Zero()),
                                   offset);
}

PlanarInertia from_point_masses(std::span<const PointMass> points) {
  PlanarInertia b;
  Eigen::Vector2d first = Eigen::Vector2d::Zero();
  double second = 0.0;  // Σ m |r|²: inertia about the link origin (eqn 4)
  for (const PointMass& p : points) {
    b.mass_kg += p.mass_kg;
    first += p.mass_kg * p.at_m;
    second += p.mass_kg * p.at_m.squaredNorm();
  }
  if (b.mass_kg == 0.0) return {};
  b.centre_m = first / b.mass_kg;
  b.inertia_kg_m2 = second - b.mass_kg * b.centre_m.squaredNorm();
  return b;
}

}  // namespace loom::motion
