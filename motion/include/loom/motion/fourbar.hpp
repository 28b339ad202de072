// Planar four-bar linkage analysis (crank input): Grashof class, closed-form position on an explicit
// assembly branch, kinematic coefficients (dθ/dθ2, d²θ/dθ2²) for velocity and acceleration at any crank
// speed law, transmission angle and dead centres. Configure-time analysis; evaluations are pure and
// allocation-free. Frame: crank pivot A0 at the origin, rocker pivot B0 at (ground, 0); angles from +x.
#pragma once

#include <cstdint>

namespace loom::motion {

struct FourBar {
  double ground = 0.0;   // d, A0B0 (m)
  double crank = 0.0;    // a, A0A
  double coupler = 0.0;  // b, AB
  double rocker = 0.0;   // c, B0B
};

enum class GrashofClass : std::uint8_t {
  kCrankRocker,     // shortest link is the crank: the crank turns fully, the rocker swings
  kDoubleCrank,     // shortest link is the ground (drag link)
  kRockerCrank,     // shortest link is the rocker: the crank cannot turn fully
  kDoubleRocker,    // Grashof, shortest link is the coupler
  kTripleRocker,    // non-Grashof: no link turns fully
  kChangePoint,     // s + l = p + q: the linkage can fold flat (branches meet)
};
const char* grashof_class_name(GrashofClass c);

// Assembly branch: on kPositive the rocker lies counter-clockwise of the line B0→A (the triangle
// A-B-B0 is traversed counter-clockwise); kNegative is its mirror image. A crank-rocker stays on one
// branch through a whole turn, so the branch is chosen once, explicitly, never guessed per sample.
enum class Branch : std::int8_t { kNegative = -1, kPositive = +1 };

// Throws MotionError(kInvalidInput) on non-positive or non-finite lengths.
GrashofClass classify(const FourBar& m);

struct FourBarPose {
  double theta2 = 0.0;  // crank angle (rad)
  double theta3 = 0.0;  // coupler angle
  double theta4 = 0.0;  // rocker angle
  // Kinematic coefficients: derivatives of θ3, θ4 with respect to the crank angle θ2.
  double k3 = 0.0, k4 = 0.0;    // dθ/dθ2
  double k3p = 0.0, k4p = 0.0;  // d²θ/dθ2²
  double transmission = 0.0;    // μ = angle between coupler and rocker in [0, π]
};

// Position and kinematic coefficients at crank angle θ2 on `branch`. Throws MotionError:
// kNotAssemblable when the loop cannot close at θ2 (beyond a rounding tolerance), kSingular when the
// coupler and rocker are colinear (toggle: the coefficients are unbounded there).
FourBarPose solve(const FourBar& m, double theta2, Branch branch);

// Time derivatives from the coefficients: ω = k·ω2, α = k·α2 + k'·ω2².
struct AngularMotion {
  double angle = 0.0, velocity = 0.0, acceleration = 0.0;
};
inline AngularMotion rocker_motion(const FourBarPose& p, double omega2, double alpha2) {
  return {p.theta4, p.k4 * omega2, p.k4 * alpha2 + p.k4p * omega2 * omega2};
}
inline AngularMotion coupler_motion(const FourBarPose& p, double omega2, double alpha2) {
  return {p.theta3, p.k3 * omega2, p.k3 * alpha2 + p.k3p * omega2 * omega2};
}

// Dead centres of a crank-rocker: crank and coupler colinear, rocker momentarily at rest.
struct DeadCentres {
  double crank_extended = 0.0;   // θ2 where crank and coupler are in line (A0-A-B), rocker at one limit
  double crank_folded = 0.0;     // θ2 where they overlap (A between A0 and B... folded back)
  double rocker_extended = 0.0;  // θ4 at the extended dead centre
  double rocker_folded = 0.0;    // θ4 at the folded dead centre
  double swing = 0.0;            // ψ = |θ4_folded - θ4_extended|
  double crank_rotation = 0.0;   // φ: crank rotation (in its turning direction, CCW) from extended to folded
  double time_ratio = 0.0;       // φ / (2π - φ) at constant crank speed
  double mu_min = 0.0;           // minimum transmission-angle deviation measure: min over the cycle of
                                 // min(μ, π - μ), attained at θ2 = 0 or π
};
// Throws MotionError(kNotCrank) unless the linkage is a crank-rocker.
DeadCentres dead_centres(const FourBar& m, Branch branch);

}  // namespace loom::motion
