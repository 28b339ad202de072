// Batten acceleration at the beat for the elliptic-gear drive of seed 004: the batten's angular
// acceleration at its beating turning points for eccentricity e and crank orientation φ02, a search
// over φ02 for the largest one, and the gain against the circular gear (e = 0). The gear's law
// φ2 = φ02 + φ2(φ1) is also offered as a crank speed law, the electronic cam a crank servo can follow
// in place of the gear. Configure-time/offline analysis (allocates, may throw MotionError).
#pragma once

#include <cstdint>
#include <vector>

#include "loom/motion/design/batten.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/elliptic_gear.hpp"

namespace loom::motion {

// Which turning points of ψ are the beat (the batten's front, where the reed meets the fell).
enum class BattenBeatSide : std::uint8_t { kPsiMax, kPsiMin };
// RT-safe. "psi-max", "psi-min".
const char* batten_beat_side_name(BattenBeatSide s);

// The batten's acceleration at the beat: the largest |ψ''| among the turning points on one side
// (004's double-swing drive beats twice per crank turn).
struct BattenBeat {
  double phi1_rad = 0.0;  // driving-pinion angle of that turning point
  double psi_rad = 0.0;
  double psi_ddot_rad_s2 = 0.0;  // signed; its magnitude is the beat acceleration
  int beats_per_turn = 0;        // turning points on the side, per driving turn
};

// Configure-time only. Throws kInvalidInput if the side has no turning point.
BattenBeat batten_beat(const BattenDrive& drive, BattenBeatSide side, double omega1_rad_s, int samples = 720);

// Configure-time only. The side whose turning points decelerate harder with the circular gear: a
// sley's front dead position is its harder one (the reed is stopped by the fell), so that is taken
// as the beat when the caller does not name it.
BattenBeatSide batten_front_side(const BattenLinkage& linkage, double omega1_rad_s = 1.0, int samples = 720);

// One visit of the batten to the beat side. 004's double swing visits each extreme twice per crank
// turn, at two fixed crank angles (turning points of ψ are where dψ/dθ2 = 0, whatever the crank speed
// law), so each visit has its own gain: at a turning point ψ'' = (d²ψ/dθ2²)·ω2², the gain of a visit
// is (ω2/ω1)² of the gear there — between ((1-e)/(1+e))² and ((1+e)/(1-e))².
struct BattenVisit {
  double crank_rad = 0.0;     // crank (driven pinion) angle of the visit, [0, 2π): fixed by the linkage
  double phi1_rad = 0.0;      // driving-pinion angle at which it happens with the gear
  double accel_rad_s2 = 0.0;  // |ψ''| there with the elliptic gear
  double circular_accel_rad_s2 = 0.0;  // ... with e = 0 at the same visit
  double gain = 0.0;                   // accel / circular, of this visit alone
};

struct BattenGain {
  double eccentricity = 0.0;
  double phi02_rad = 0.0;
  BattenBeatSide side = BattenBeatSide::kPsiMin;
  double accel_rad_s2 = 0.0;           // |ψ''| at the beat with the elliptic gear
  double circular_accel_rad_s2 = 0.0;  // ... with e = 0 (any φ02: it only shifts the motion)
  double gain = 0.0;                   // accel / circular: the largest |ψ''| over the visits with the gear
                                       // against the largest with e = 0 (possibly different visits)
  double phi1_rad = 0.0;               // where the beat happens
  std::vector<BattenVisit> visits;     // every visit to the side, in order of crank angle
  int beat_visit = 0;                  // index into visits of the beat: the visit that decelerates
                                       // hardest with the circular gear (where the reed meets the fell)
};

// Configure-time only. Gain at one φ02.
BattenGain batten_gain(const BattenLinkage& linkage, const EllipticGearPair& gear, double phi02_rad,
                       BattenBeatSide side, double omega1_rad_s = 1.0, int samples = 720);

struct BattenSearch {
  BattenGain best;
  std::vector<BattenGain> scan;  // the coarse scan over one period of φ02
};

// Configure-time only. Scan φ02 over one period (2π/k: shifting φ02 and φ1 together by 2π/k repeats
// the motion) at scan_points, then refine the best by golden section between its neighbours.
BattenSearch batten_best_phi02(const BattenLinkage& linkage, const EllipticGearPair& gear,
                               BattenBeatSide side, double omega1_rad_s = 1.0, int scan_points = 360,
                               int samples = 720);

// RT-safe. The geared crank's motion at driving angle φ1, speed ω1, acceleration α1: the crank law a
// servo follows to reproduce the gear electronically.
CrankMotion elliptic_gear_crank(const EllipticGearPair& gear, double phi02_rad, double phi1_rad,
                                double omega1_rad_s, double alpha1_rad_s2 = 0.0);

}  // namespace loom::motion
