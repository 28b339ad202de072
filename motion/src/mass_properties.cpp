// Link mass properties from geometry and material. The formulas are the textbook ones; the checks
// exist because a zero or negative density/length would silently give a massless linkage whose
// dynamics look perfectly plausible.
#include "loom/motion/mass_properties.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

void require_positive(const char* what, double v, const char* unit) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    std::ostringstream os;
    os << "mass properties: " << what << " = " << v << ' ' << unit << ": must be finite and > 0";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
}

}  // namespace

PlanarInertia bar_link(double length_m, const BarSection& section, double density_kg_m3) {
  require_positive("bar length", length_m, "m");
  require_positive("bar width", section.width_m, "m");
  require_positive("bar thickness", section.thickness_m, "m");
  require_positive("density", density_kg_m3, "kg/m^3");
  PlanarInertia p;
  p.mass_kg = density_kg_m3 * length_m * section.width_m * section.thickness_m;
  p.centre_m = {0.5 * length_m, 0.0};
  p.inertia_kg_m2 = p.mass_kg * (length_m * length_m + section.width_m * section.width_m) / 12.0;
  return p;
}

PlanarInertia point_mass(double mass_kg, const Eigen::Vector2d& at_m) {
  if (!(mass_kg >= 0.0) || !std::isfinite(mass_kg) || !at_m.allFinite()) {
    std::ostringstream os;
    os << "mass properties: point mass " << mass_kg << " kg at (" << at_m.x() << ", " << at_m.y()
       << ") m: mass must be finite and >= 0, position finite";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  return {mass_kg, at_m, 0.0};
}

PlanarInertia combine(const PlanarInertia& a, const PlanarInertia& b) {
  PlanarInertia c;
  c.mass_kg = a.mass_kg + b.mass_kg;
  if (c.mass_kg <= 0.0) return c;  // two massless bodies: nothing to place
  c.centre_m = (a.mass_kg * a.centre_m + b.mass_kg * b.centre_m) / c.mass_kg;
  c.inertia_kg_m2 = a.inertia_about(c.centre_m) + b.inertia_about(c.centre_m);
  return c;
}

BeatUpMasses beatup_masses(const BeatUpGeometry& g, double beater_kg, const BarSection& section,
                           double density_kg_m3) {
  if (!(beater_kg >= 0.0) || !std::isfinite(beater_kg)) {
    std::ostringstream os;
    os << "mass properties: beater mass = " << beater_kg << " kg: must be finite and >= 0";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  require_positive("beater arm", g.beater_arm_m, "m");
  BeatUpMasses m;
  m.crank = bar_link(g.bar.crank, section, density_kg_m3);
  m.coupler = bar_link(g.bar.coupler, section, density_kg_m3);
  m.rocker = bar_link(std::max(g.bar.rocker, g.beater_arm_m), section, density_kg_m3);
  m.beater_kg = beater_kg;
  m.beater_at_m = {g.beater_arm_m, 0.0};
  return m;
}

}  // namespace loom::motion
