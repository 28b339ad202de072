// Elliptic (k-lobed) toothed gear pair of the batten drive (seed 004): two identical pitch curves
// r = p/(1 + e·cos kφ) meshing at centre distance 2a turn a uniform input φ1 into a variable output
// φ2(φ1). Everything here is closed form, so the driven angle has no branch jumps over any number of
// turns, and e = 0 is exactly the circular (constant-ratio) gear.
#pragma once

namespace loom::motion {

// Driven-pinion angle and its derivatives with respect to the driving pinion angle φ1.
struct GearPhase {
  double phi2_rad;  // φ2(φ1), continuous and unbounded (one driven turn per driver turn)
  double dphi2;     // dφ2/dφ1 = 1/i12 (dimensionless)
  double d2phi2;    // d²φ2/dφ1² (1/rad)
};

class EllipticGearPair {
 public:
  // Above this speed-ratio spread max(dφ2/dφ1) = (1+e)/(1-e) — e > 99/101 ≈ 0.980 — a crank-angle
  // error is amplified a hundred-fold and accelerations and forces (which go with the ratio's square)
  // ten-thousand-fold: the results stay finite but the gear is flagged as near-degenerate (e -> 1).
  // e = 0.99 (ratio 199, squared 39 601) is flagged; no cut gear comes near it.
  static constexpr double kNearDegenerateSpeedRatio = 1.0e2;

  // Configure-time only. half_centre_distance_m = a (centre distance 2a), eccentricity e in [0, 1),
  // lobes k >= 1 (004 uses k = 2). Throws MotionError(kInvalidInput) naming the bad field.
  EllipticGearPair(double half_centre_distance_m, double eccentricity, int lobes = 2);

  // RT-safe. Pitch radius of the driving pinion at its contact point, r1 = p/(1 + e cos kφ1) (m).
  double driver_radius_m(double phi1_rad) const;
  // RT-safe. Pitch radius of the driven pinion at the same contact, r2 = 2a - r1 (m).
  double driven_radius_m(double phi1_rad) const;
  // RT-safe. Gear-ratio function i12 = dφ1/dφ2 = r2/r1 (004 eqn 6 for k = 2).
  double ratio(double phi1_rad) const;
  // RT-safe. φ2 = ∫0^φ1 r1/(2a - r1) dφ1 in closed form, with first and second derivatives.
  GearPhase phase(double phi1_rad) const;

  // RT-safe accessors and flags (below).
  double half_centre_distance_m() const { return a_m_; }
  double eccentricity() const { return e_; }
  int lobes() const { return k_; }
  // Pitch-curve parameter p = b²/a = a(1 - e²) (m).
  double semi_latus_rectum_m() const { return a_m_ * (1.0 - e_) * (1.0 + e_); }
  // (1+e)/(1-e): the largest dφ2/dφ1; its inverse is the smallest.
  double max_speed_ratio() const;
  // e -> 1: finite but ill-conditioned (see kNearDegenerateSpeedRatio).
  bool near_degenerate() const { return max_speed_ratio() > kNearDegenerateSpeedRatio; }
  // k >= 2 and e > 1/(k² - 1): the pitch curve has concave stretches and cannot be cut as a gear.
  bool concave_pitch_curve() const;

 private:
  double a_m_;
  double e_;
  int k_;
};

}  // namespace loom::motion
