// Beat acceleration of the geared batten drive (004). The turning points come from the kinematics
// module's bisection on ψ' (exact to rounding), so the only approximation here is the φ02 search,
// whose golden refinement runs until the bracket is below 1e-10 rad.
#include "loom/motion/design/dynamics_batten.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

void require_speed(double omega1) {
  if (!(omega1 > 0.0) || !std::isfinite(omega1)) {
    std::ostringstream os;
    os << "batten beat: omega1 = " << omega1 << " rad/s: must be finite and > 0";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
}

}  // namespace

const char* batten_beat_side_name(BattenBeatSide s) {
  return s == BattenBeatSide::kPsiMax ? "psi-max" : "psi-min";
}

BattenBeat batten_beat(const BattenDrive& drive, BattenBeatSide side, double omega1, int samples) {
  require_speed(omega1);
  BattenBeat b;
  const bool want_max = side == BattenBeatSide::kPsiMax;
  for (const BattenExtreme& x : batten_extremes(drive, samples, omega1)) {
    if (x.maximum != want_max) continue;
    ++b.beats_per_turn;
    if (std::abs(x.psi_ddot_rad_s2) > std::abs(b.psi_ddot_rad_s2)) {
      b.phi1_rad = x.phi1_rad;
      b.psi_rad = x.psi_rad;
      b.psi_ddot_rad_s2 = x.psi_ddot_rad_s2;
    }
  }
  if (b.beats_per_turn == 0) {
    throw MotionError(
        ErrorCode::kInvalidInput,
        std::string("batten beat: the batten has no turning point on side ") + batten_beat_side_name(side));
  }
  return b;
}

BattenBeatSide batten_front_side(const BattenLinkage& linkage, double omega1, int samples) {
  const BattenDrive circular(EllipticGearPair(kBatten004GearA_m, 0.0, 2), linkage, 0.0);
  const double at_max =
      std::abs(batten_beat(circular, BattenBeatSide::kPsiMax, omega1, samples).psi_ddot_rad_s2);
  const double at_min =
      std::abs(batten_beat(circular, BattenBeatSide::kPsiMin, omega1, samples).psi_ddot_rad_s2);
  return at_max >= at_min ? BattenBeatSide::kPsiMax : BattenBeatSide::kPsiMin;
}

namespace {

// The turning points on one side, each with the crank angle that identifies it.
std::vector<BattenVisit> visits_of(const BattenDrive& drive, BattenBeatSide side, double omega1,
                                   int samples) {
  std::vector<BattenVisit> v;
  const bool want_max = side == BattenBeatSide::kPsiMax;
  for (const BattenExtreme& x : batten_extremes(drive, samples, omega1)) {
    if (x.maximum != want_max) continue;
    BattenVisit b;
    b.crank_rad = wrap_two_pi(drive.evaluate(x.phi1_rad, omega1).phi2_rad);
    b.phi1_rad = x.phi1_rad;
    b.accel_rad_s2 = std::abs(x.psi_ddot_rad_s2);
    v.push_back(b);
  }
  std::sort(v.begin(), v.end(),
            [](const BattenVisit& a, const BattenVisit& b) { return a.crank_rad < b.crank_rad; });
  return v;
}

}  // namespace

BattenGain batten_gain(const BattenLinkage& linkage, const EllipticGearPair& gear, double phi02,
                       BattenBeatSide side, double omega1, int samples) {
  const EllipticGearPair circular(gear.half_centre_distance_m(), 0.0, gear.lobes());
  const BattenBeat ref = batten_beat(BattenDrive(circular, linkage, 0.0), side, omega1, samples);
  const BattenBeat b = batten_beat(BattenDrive(gear, linkage, phi02), side, omega1, samples);
  BattenGain g;
  g.eccentricity = gear.eccentricity();
  g.phi02_rad = phi02;
  g.side = side;
  g.accel_rad_s2 = std::abs(b.psi_ddot_rad_s2);
  g.circular_accel_rad_s2 = std::abs(ref.psi_ddot_rad_s2);
  g.gain = g.accel_rad_s2 / g.circular_accel_rad_s2;
  g.phi1_rad = b.phi1_rad;
  // Per visit: the same crank angle with and without the gear (matched by nearest crank angle).
  const std::vector<BattenVisit> circ = visits_of(BattenDrive(circular, linkage, 0.0), side, omega1, samples);
  g.visits = visits_of(BattenDrive(gear, linkage, phi02), side, omega1, samples);
  double hardest = -1.0;
  for (std::size_t i = 0; i < g.visits.size(); ++i) {
    BattenVisit& v = g.visits[i];
    const BattenVisit* match = nullptr;
    for (const BattenVisit& c : circ) {
      if (match == nullptr ||
          std::abs(wrap_pi(c.crank_rad - v.crank_rad)) < std::abs(wrap_pi(match->crank_rad - v.crank_rad))) {
        match = &c;
      }
    }
    if (match == nullptr) continue;
    v.circular_accel_rad_s2 = match->accel_rad_s2;
    v.gain = v.accel_rad_s2 / v.circular_accel_rad_s2;
    if (match->accel_rad_s2 > hardest) {
      hardest = match->accel_rad_s2;
      g.beat_visit = static_cast<int>(i);
    }
  }
  return g;
}

BattenSearch batten_best_phi02(const BattenLinkage& linkage, const EllipticGearPair& gear,
                               BattenBeatSide side, double omega1, int scan_points, int samples) {
  if (scan_points < 3) {
    throw MotionError(ErrorCode::kInvalidInput,
                      "batten phi02 search: scan points = " + std::to_string(scan_points) + ": must be >= 3");
  }
  const double period = kTwoPi / gear.lobes();
  const auto accel = [&](double phi02) {
    return std::abs(batten_beat(BattenDrive(gear, linkage, phi02), side, omega1, samples).psi_ddot_rad_s2);
  };
  BattenSearch s;
  std::size_t best = 0;
  for (int i = 0; i < scan_points; ++i) {
    const double phi02 = period * i / scan_points;
    BattenGain g = batten_gain(linkage, gear, phi02, side, omega1, samples);
    if (s.scan.empty() || g.gain > s.scan[best].gain) best = s.scan.size();
    s.scan.push_back(g);
  }
  // Golden section between the best sample's neighbours (the maximum of several smooth branches is
  // unimodal on that bracket at this resolution).
  const double step = period / scan_points;
  double lo = s.scan[best].phi02_rad - step, hi = s.scan[best].phi02_rad + step;
  const double inv_phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - inv_phi * (hi - lo), x2 = lo + inv_phi * (hi - lo);
  double f1 = accel(x1), f2 = accel(x2);
  while (hi - lo > 1e-10) {
    if (f1 < f2) {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + inv_phi * (hi - lo);
      f2 = accel(x2);
    } else {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - inv_phi * (hi - lo);
      f1 = accel(x1);
    }
  }
  const double phi = 0.5 * (lo + hi);
  s.best = s.scan[best];
  if (accel(phi) >= s.best.accel_rad_s2) {
    s.best = batten_gain(linkage, gear, phi, side, omega1, samples);
  }
  s.best.phi02_rad = std::fmod(std::fmod(s.best.phi02_rad, period) + period, period);
  return s;
}

CrankMotion elliptic_gear_crank(const EllipticGearPair& gear, double phi02, double phi1, double omega1,
                                double alpha1) {
  const GearPhase g = gear.phase(phi1);
  return {phi02 + g.phi2_rad, g.dphi2 * omega1, g.d2phi2 * omega1 * omega1 + g.dphi2 * alpha1};
}

}  // namespace loom::motion
