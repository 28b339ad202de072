// Elliptic k-lobed gear pair in closed form (seed 004, eqns 2-6 and 8, generalised from k = 2).
// The integral φ2 = ∫ (1-e²)/(1 + e² + 2e cos kφ1) dφ1 is the focal-ellipse law
// tan(kφ2/2) = q·tan(kφ1/2), q = (1-e)/(1+e), unrolled onto the right tread so it is continuous and
// monotone for any number of turns and keeps full relative accuracy on the treads as e -> 1.
#include "loom/motion/elliptic_gear.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

[[noreturn]] void bad(const char* field, double value, const char* why) {
  std::ostringstream os;
  os << "elliptic gear: " << field << " = " << value << ": " << why;
  throw MotionError(ErrorCode::kInvalidInput, os.str());
}

// 1 + e² + 2e·cos u, written as (1-e)² + 4e·cos²(u/2) so it keeps full relative accuracy where it
// is smallest (e -> 1, cos u -> -1) instead of cancelling to zero.
double ratio_denominator(double e, double u) {
  const double c = std::cos(0.5 * u);
  return (1.0 - e) * (1.0 - e) + 4.0 * e * c * c;
}

}  // namespace

EllipticGearPair::EllipticGearPair(double half_centre_distance_m, double eccentricity, int lobes)
    : a_m_(half_centre_distance_m), e_(eccentricity), k_(lobes) {
  if (!std::isfinite(a_m_) || a_m_ <= 0.0) bad("a", a_m_, "half centre distance must be > 0 m");
  if (!std::isfinite(e_) || e_ < 0.0 || e_ >= 1.0)
    bad("e", e_, "eccentricity must be in [0, 1) (e >= 1 is an open curve, not a gear)");
  if (k_ < 1) bad("k", static_cast<double>(k_), "number of lobes must be >= 1");
}

double EllipticGearPair::driver_radius_m(double phi1_rad) const {
  return semi_latus_rectum_m() / (1.0 + e_ * std::cos(k_ * phi1_rad));
}

double EllipticGearPair::driven_radius_m(double phi1_rad) const {
  // 2a - p/(1 + e cos u) = a(1 + e² + 2e cos u)/(1 + e cos u): no cancellation between 2a and r1.
  const double u = k_ * phi1_rad;
  return a_m_ * ratio_denominator(e_, u) / (1.0 + e_ * std::cos(u));
}

double EllipticGearPair::ratio(double phi1_rad) const {
  return ratio_denominator(e_, k_ * phi1_rad) / ((1.0 - e_) * (1.0 + e_));
}

GearPhase EllipticGearPair::phase(double phi1_rad) const {
  const double u = k_ * phi1_rad;
  const double su = std::sin(u);
  const double one_minus_e2 = (1.0 - e_) * (1.0 + e_);
  const double den = ratio_denominator(e_, u);
  GearPhase g{};
  // d/dφ1 of (2/k)·atan(q tan(u/2)) = q/(cos²(u/2) + q² sin²(u/2)) = (1 - e²)/den: 004's eqn 5
  // integrand, so the closed form and its derivatives are the same law.
  if (e_ == 0.0) {
    g.phi2_rad = phi1_rad;  // the circular gear is the identity, exactly
  } else {
    // Tread n holds kφ1/2 in [nπ - π/2, nπ + π/2]; on it kφ2/2 = nπ + atan(q tan(kφ1/2 - nπ)), and
    // neighbouring treads meet at the same value, so φ2 is continuous across them. Unlike
    // φ1 - atan2(...), this has no cancellation where the pinion nearly stands still (e -> 1).
    const double half = 0.5 * u;
    double n = std::nearbyint(half / kPi);
    double h = half - n * kPi;
    // Rounding can leave h a hair beyond ±π/2 at a tread edge, where tan changes sign: step over.
    if (h > 0.5 * kPi) {
      n += 1.0;
      h -= kPi;
    } else if (h < -0.5 * kPi) {
      n -= 1.0;
      h += kPi;
    }
    const double q = (1.0 - e_) / (1.0 + e_);
    g.phi2_rad = (2.0 / k_) * (n * kPi + std::atan(q * std::tan(h)));
  }
  g.dphi2 = one_minus_e2 / den;
  g.d2phi2 = 2.0 * e_ * k_ * su * one_minus_e2 / (den * den);
  return g;
}

double EllipticGearPair::max_speed_ratio() const {
  return (1.0 + e_) / (1.0 - e_);
}

bool EllipticGearPair::concave_pitch_curve() const {
  // Curvature of r = p/(1 + e cos kφ) changes sign exactly when e exceeds 1/(k² - 1).
  if (k_ < 2) return false;
  const double kk = static_cast<double>(k_);
  return e_ > 1.0 / (kk * kk - 1.0);
}

}  // namespace loom::motion
