// Planar four-bar linkage analysis (crank input): Grashof class, closed-form position on an explicit
// assembly branch, kinematic coefficients (dθ/dθ2, d²θ/dθ2²) for velocity and acceleration at any crank
// speed law, points on any link, a whole-turn sweep, transmission angle, dead centres, and Newton on
// the loop closure for comparison. Configure-time analysis; evaluations are pure and allocation-free.
// Frame: crank pivot A0 at the origin, rocker pivot B0 at (ground, 0); angles from +x.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "loom/motion/link_point.hpp"
#include "loom/motion/newton.hpp"

namespace loom::motion {

struct FourBar {
  double ground = 0.0;   // d, A0B0 (m)
  double crank = 0.0;    // a, A0A
  double coupler = 0.0;  // b, AB
  double rocker = 0.0;   // c, B0B
};

enum class GrashofClass : std::uint8_t {
  kCrankRocker,   // shortest link is the crank: the crank turns fully, the rocker swings
  kDoubleCrank,   // shortest link is the ground (drag link)
  kRockerCrank,   // shortest link is the rocker: the crank cannot turn fully
  kDoubleRocker,  // Grashof, shortest link is the coupler
  kTripleRocker,  // non-Grashof: no link turns fully
  kChangePoint,   // s + l = p + q: the linkage can fold flat (branches meet)
};
// RT-safe. A short fixed name for messages and CSV.
const char* grashof_class_name(GrashofClass c);

// Assembly branch: on kPositive the rocker lies counter-clockwise of the line B0→A (the triangle
// A-B-B0 is traversed counter-clockwise); kNegative is its mirror image. A crank-rocker stays on one
// branch through a whole turn, so the branch is chosen once, explicitly, never guessed per sample.
enum class Branch : std::int8_t { kNegative = -1, kPositive = +1 };

// configure-time only. Throws MotionError(kInvalidInput) on non-positive or non-finite lengths.
GrashofClass classify(const FourBar& m);

// Position only: defined wherever the loop closes, including the toggle (limit) poses where the
// coefficients are not.
struct FourBarPosition {
  double theta2 = 0.0, theta3 = 0.0, theta4 = 0.0;  // crank, coupler, rocker angles (rad)
  double transmission = 0.0;                        // μ = angle between coupler and rocker in [0, π]
  bool at_toggle = false;  // coupler and rocker colinear: |sin μ| < 1e-12, or the loop's
                           // triangle (B0, A, B) height rounded to zero or below and was clamped;
                           // both branches meet here and the rates are unbounded
};

// configure-time only (throws). Position on `branch` at crank angle θ2. Throws MotionError
// kInvalidInput (bad lengths or θ2), kNotAssemblable when the loop misses closing by more than
// 1e-12 of the largest link; a miss within that is rounding, clamped and flagged `at_toggle`.
FourBarPosition solve_position(const FourBar& m, double theta2, Branch branch);

struct FourBarPose {
  double theta2 = 0.0;  // crank angle (rad)
  double theta3 = 0.0;  // coupler angle
  double theta4 = 0.0;  // rocker angle
  // Kinematic coefficients: derivatives of θ3, θ4 with respect to the crank angle θ2.
  double k3 = 0.0, k4 = 0.0;    // dθ/dθ2
  double k3p = 0.0, k4p = 0.0;  // d²θ/dθ2²
  double transmission = 0.0;    // μ = angle between coupler and rocker in [0, π]
};

// configure-time only (throws). Position and kinematic coefficients at crank angle θ2 on `branch`.
// Throws as solve_position, and kSingular at a pose solve_position flags `at_toggle` (toggle or
// change point: the coefficients are unbounded there).
FourBarPose solve(const FourBar& m, double theta2, Branch branch);

// RT-safe. The branch a pose (θ3, θ4) lies on: the sign of sin(θ3 − θ4), which is also the sign of
// the loop-closure Jacobian's determinant b·c·sin(θ3 − θ4).
Branch branch_of(double theta3, double theta4);

// Time derivatives from the coefficients: ω = k·ω2, α = k·α2 + k'·ω2².
struct AngularMotion {
  double angle = 0.0, velocity = 0.0, acceleration = 0.0;
};
// RT-safe.
inline AngularMotion rocker_motion(const FourBarPose& p, double omega2, double alpha2) {
  return {p.theta4, p.k4 * omega2, p.k4 * alpha2 + p.k4p * omega2 * omega2};
}
// RT-safe.
inline AngularMotion coupler_motion(const FourBarPose& p, double omega2, double alpha2) {
  return {p.theta3, p.k3 * omega2, p.k3 * alpha2 + p.k3p * omega2 * omega2};
}

// The moving links, each with its own frame: origin at its first pivot, x along the link.
enum class FourBarLink : std::uint8_t {
  kCrank,    // origin A0, x towards A
  kCoupler,  // origin A, x towards B
  kRocker,   // origin B0, x towards B
};

// RT-safe. Position and its derivatives with respect to θ2 of the point `local` on `link` at `pose`
// (use point_motion() for velocity and acceleration). `m` must be the linkage `pose` was solved for.
PointCoefficients point_coefficients(const FourBar& m, const FourBarPose& pose, FourBarLink link,
                                     const Eigen::Vector2d& local);

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
// configure-time only. Throws MotionError(kNotCrank) unless the linkage is a crank-rocker.
DeadCentres dead_centres(const FourBar& m, Branch branch);

// Transmission angle over a whole crank turn. μ grows with the diagonal |A B0|, which runs from
// |d − a| at θ2 = 0 to d + a at θ2 = π, so both extremes are closed forms (and branch-independent).
// |sin μ| below this somewhere in the turn is a near toggle: the linkage turns, but its rates there
// are amplified by 1/|sin μ| > 1000 and small length errors move it a long way — flagged, not refused.
inline constexpr double kNearToggleSine = 1e-3;

struct TransmissionRange {
  double mu_min = 0.0;                      // smallest μ over the turn (rad), at θ2 = 0
  double mu_max = 0.0;                      // largest μ over the turn, at θ2 = π
  double worst_deviation_from_right = 0.0;  // max over the turn of |μ − π/2|
  double min_abs_sin_mu = 0.0;              // min over the turn of |sin μ| (at μ_min or μ_max)
  bool near_toggle = false;                 // min_abs_sin_mu < kNearToggleSine
};
// configure-time only. For a linkage whose crank turns fully (crank-rocker, double-crank); throws
// kNotCrank otherwise, kInvalidInput on bad lengths. Accurate for needle-like triangles (Kahan).
TransmissionRange transmission_range(const FourBar& m);

// configure-time only (allocates). One crank turn, θ2 = θ2_start + 2π·i/samples, on `branch`; θ3 and
// θ4 are unwrapped against the previous sample so each column is continuous (a double-crank's
// rocker gains 2π per turn). Throws kInvalidInput (samples < 1, non-finite start), kNotCrank unless
// the crank turns fully, kSingular for a change-point linkage (its branches meet at the flat pose,
// so which way it moves on from there is not determined by the geometry).
std::vector<FourBarPose> fourbar_sweep(const FourBar& m, Branch branch, int samples,
                                       double theta2_start = 0.0);
// configure-time only. The same sweep handed to `sink` one pose at a time, in constant memory (the
// offline tools stream millions of samples this way). Throws as above, before the first pose.
void fourbar_sweep(const FourBar& m, Branch branch, int samples, double theta2_start,
                   const std::function<void(const FourBarPose&)>& sink);

// What a sweep over the crank angles a linkage can reach covered.
struct ReachableSweep {
  int solved = 0;       // poses handed to the sink
  int unreachable = 0;  // crank angles where the loop does not close (outside the input link's range)
  int at_toggle = 0;    // crank angles at a toggle (coefficients unbounded), within rounding
};
// configure-time only. The same samples as fourbar_sweep for a linkage whose input link cannot turn
// fully (double-rocker, rocker-crank, triple-rocker) as well as for one that can: each pose is solved
// on `branch` independently, and crank angles it cannot reach or where it is at a toggle are skipped
// and counted instead of ending the sweep. Angles are unwrapped only across consecutive solved poses.
// Throws kInvalidInput (samples < 1, non-finite start, bad lengths) and kSingular for a change-point
// linkage, before the first pose.
// The sink gets the sample's index i (θ2 = θ2_start + 2π·i/samples) with the pose.
ReachableSweep fourbar_sweep_reachable(const FourBar& m, Branch branch, int samples, double theta2_start,
                                       const std::function<void(int, const FourBarPose&)>& sink);

struct FourBarNewtonResult {
  FourBarPose pose;  // coefficients from the converged angles
  int iterations;    // Newton steps taken (0 when the guess already met the tolerance)
  double residual;   // max|F_i| of the loop closure at the returned angles (length unit of m)
};

// configure-time only. Newton on the loop closure a·e^{iθ2} + b·e^{iθ3} − d − c·e^{iθ4} = 0 in (θ3, θ4)
// from a guess — the numerical route the closed form is measured against. Throws MotionError
// kInvalidInput (bad options, non-finite guess), kSingular (Jacobian b·c·sin(θ3 − θ4) vanishes on
// the way: toggle), kNoConvergence (budget spent), kWrongBranch (converged to the mirror assembly).
FourBarNewtonResult solve_newton(const FourBar& m, double theta2, Branch branch, double theta3_guess,
                                 double theta4_guess, const NewtonOptions& opt = {});

}  // namespace loom::motion
