// Batten drive of seed 004: an elliptic gear turns the crank L1 (fixed to the driven pinion) of a
// crank-and-two-rocker linkage, eqns (7), whose second rocker L5 is the batten. Positions in closed
// form (two circle intersections on named sides) or by Newton on eqns (7) with the assembly branch
// checked after convergence; batten angle ψ with exact first and second time derivatives.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "loom/motion/elliptic_gear.hpp"
#include "loom/motion/newton.hpp"

namespace loom::motion {

// Link lengths and ground offsets of eqns (7), m. Frame: origin at the crank pivot O1, x right,
// y up. Reading eqns (7) as vector loops puts the rocker pivot O3 at (-L7, L6) and the batten pivot
// P at (L9, 2·L6 + L8).
struct BattenDims {
  double l1_m;  // crank O1-A (rigid with the driven pinion)
  double l2_m;  // coupler A-B; 004 measures its angle γ2 from the y axis: B - A = L2 (sin γ2, cos γ2)
  double l3_m;  // first rocker O3-B at angle γ3: B - O3 = L3 (cos γ3, sin γ3)
  double l4_m;  // second coupler D-B at angle γ4: B - D = L4 (cos γ4, sin γ4)
  double l5_m;  // batten P-D at angle ψ from the y axis: D - P = L5 (-sin ψ, cos ψ)
  double l6_m, l7_m, l8_m, l9_m;  // ground offsets as they appear in eqns (7)
};

// Configure-time only. 004's dimensions: L1..L9 = 0.04, 0.09, 0.08, 0.09, 0.17, 0.1, 0.06, 0.05, 0.11 m.
BattenDims batten_004_dims();
// 004's gear: a = 0.05 m with k = 2 lobes (e is the experiment's variable).
inline constexpr double kBatten004GearA_m = 0.05;

enum class LoopSide { kLeft, kRight };

// Assembly branch: loop 1 — B on the left or right of the directed line A -> O3; loop 2 — D on the
// left or right of B -> P. Equivalently the signs of the two 2×2 blocks of the eqns (7) Jacobian:
// det1 = -L2 L3 cos(γ2 + γ3) > 0 is loop-1 left, det2 = L4 L5 cos(γ4 - ψ) < 0 is loop-2 left.
// The default (right, right) is the one whose batten swings twice per crank turn, as 004 describes.
struct BattenBranch {
  LoopSide loop1 = LoopSide::kRight;
  LoopSide loop2 = LoopSide::kRight;
  bool operator==(const BattenBranch&) const = default;
};

// The unknowns x = (γ2, γ3, γ4, ψ) of eqns (7), rad. vec()/from() are RT-safe conversions.
struct BattenPose {
  double gamma2_rad, gamma3_rad, gamma4_rad, psi_rad;
  Eigen::Vector4d vec() const { return {gamma2_rad, gamma3_rad, gamma4_rad, psi_rad}; }
  static BattenPose from(const Eigen::Vector4d& x) { return {x(0), x(1), x(2), x(3)}; }
};

// First and second time derivatives of the pose.
struct BattenRates {
  Eigen::Vector4d dot;   // (γ2', γ3', γ4', ψ') rad/s
  Eigen::Vector4d ddot;  // (γ2'', γ3'', γ4'', ψ'') rad/s²
};

struct NewtonResult {
  BattenPose pose;
  int iterations;     // Newton steps taken (0 when the guess already met the tolerance)
  double residual_m;  // max|F_i| at the returned pose
};

class BattenLinkage {
 public:
  // Configure-time only. Validates once so that solve() is defined for every crank angle: throws
  // MotionError kInvalidInput (non-finite or non-positive length), kNotCrank (L1 cannot turn fully),
  // kSingular (change point, or loop 2 reaches a toggle within the L3 swing), kNotAssemblable
  // (loop 2 cannot close somewhere in the swing).
  explicit BattenLinkage(const BattenDims& dims, BattenBranch branch = {});

  // RT-safe. Closed-form pose at crank angle φ2 on this linkage's branch. γ's in (-π, π],
  // ψ in [0, 2π) (004's batten hangs near ψ = π).
  BattenPose solve(double crank_rad) const;

  // Configure-time only. Newton's method on eqns (7) from `guess`, then the branch check: throws
  // kNoConvergence (budget spent), kSingular (Jacobian singular on the way), kWrongBranch
  // (converged, but to the other assembly), kInvalidInput (bad options).
  NewtonResult solve_newton(double crank_rad, const BattenPose& guess, const NewtonOptions& opt = {}) const;

  // RT-safe. F(x) of eqns (7), m.
  Eigen::Vector4d residual(double crank_rad, const BattenPose& x) const;
  // RT-safe. dF/dx (block lower-triangular: loop 1 does not see γ4, ψ).
  Eigen::Matrix4d jacobian(const BattenPose& x) const;
  // RT-safe. Which assembly a pose is in (from the signs of the two loop determinants).
  BattenBranch branch_of(const BattenPose& x) const;

  // RT-safe. Pose rates for crank rate φ2' and acceleration φ2'' (rad/s, rad/s²), by solving the
  // differentiated eqns (7) J·x' = -F_φ·φ2' and J·x'' = -F_φ·φ2'' - (centripetal terms).
  BattenRates rates(double crank_rad, const BattenPose& x, double crank_rate, double crank_accel) const;

  // γ3 at loop 1's dead centres (crank and coupler collinear): the limits of the L3 swing.
  struct RockerLimits {
    double extended_rad;
    double folded_rad;
  };
  // RT-safe accessors.
  RockerLimits rocker_limits() const { return limits_; }
  double largest_link_m() const { return scale_m_; }
  const BattenDims& dims() const { return d_; }
  BattenBranch branch() const { return branch_; }

 private:
  BattenDims d_;
  BattenBranch branch_;
  RockerLimits limits_{};
  double scale_m_ = 0.0;
};

// One instant of the geared batten drive.
struct BattenSample {
  double phi1_rad;         // driving pinion angle
  double phi2_rad;         // crank = driven pinion angle, φ02 + ∫ r1/(2a - r1) dφ1 (continuous)
  double psi_rad;          // batten angle
  double psi_dot_rad_s;    // dψ/dt
  double psi_ddot_rad_s2;  // d²ψ/dt²
  BattenPose pose;
  BattenRates rates;
};

class BattenDrive {
 public:
  // Configure-time only. φ02 is the crank's angle on the driven pinion (004 eqn 8); throws
  // MotionError kInvalidInput if it is not finite.
  BattenDrive(const EllipticGearPair& gear, const BattenLinkage& linkage, double phi02_rad);

  // RT-safe. Closed-form sample at driving-pinion angle φ1, speed ω1 and acceleration α1.
  BattenSample evaluate(double phi1_rad, double omega1_rad_s, double alpha1_rad_s2 = 0.0) const;
  // Configure-time only. Same through Newton from `guess` (see BattenLinkage::solve_newton).
  BattenSample evaluate_newton(double phi1_rad, double omega1_rad_s, const BattenPose& guess,
                               const NewtonOptions& opt = {}, int* iterations = nullptr) const;

  // RT-safe accessors.
  const EllipticGearPair& gear() const { return gear_; }
  const BattenLinkage& linkage() const { return linkage_; }
  double phi02_rad() const { return phi02_rad_; }

 private:
  EllipticGearPair gear_;
  BattenLinkage linkage_;
  double phi02_rad_;
};

enum class BattenSolver { kClosedForm, kNewton };

// Configure-time only (allocates). One driving-pinion turn, φ1 = 2π·i/samples at constant ω1.
// kNewton continues from the previous sample's pose (the first is seeded by the closed form) and
// checks the branch at every sample. Angles are unwrapped so every column is continuous.
// Throws kInvalidInput for samples < 1 or a non-finite ω1, and whatever Newton throws.
std::vector<BattenSample> batten_sweep(const BattenDrive& drive, int samples, double omega1_rad_s,
                                       BattenSolver solver = BattenSolver::kClosedForm,
                                       const NewtonOptions& opt = {});
// Configure-time only. The same sweep handed to `sink` one sample at a time, in constant memory.
void batten_sweep(const BattenDrive& drive, int samples, double omega1_rad_s,
                  const std::function<void(const BattenSample&)>& sink,
                  BattenSolver solver = BattenSolver::kClosedForm, const NewtonOptions& opt = {});

// A turning point of the batten: ψ' = 0 (a dead position; 004's beat happens at the front one).
struct BattenExtreme {
  double phi1_rad;         // driving-pinion angle of the turning point, in [0, 2π)
  double psi_rad;          // batten angle there
  double psi_ddot_rad_s2;  // batten acceleration there (at the sweep's ω1)
  bool maximum;            // ψ has a local maximum (else a minimum)
};

// Configure-time only (allocates). Every turning point of ψ over one driving turn: sign changes of
// ψ' between `samples` closed-form samples, each refined by bisection on ψ' to full precision.
std::vector<BattenExtreme> batten_extremes(const BattenDrive& drive, int samples, double omega1_rad_s);

}  // namespace loom::motion
