// Needle multi-linkage of a carpet tufting machine (seed 002): a crank-rocker O-A-B-C (l1, l2, l3)
// whose rocker carries, at the fixed angle β1, the arm l4 of an offset rocker-slider C-D-E (l4, l5)
// that drives the needle bar l6 up and down. Closed-form positions on an explicit assembly branch
// (no asin/acos quadrant traps), exact velocities and accelerations. Angles and names follow 002.
#pragma once

#include <functional>
#include <vector>

namespace loom::motion {

// Geometry in SI (m, rad). Frame: origin at the main shaft O, x horizontal towards the rocker pivot
// side, y up. Rocker pivot C = (x1, H1); the needle bar slides on the vertical line x = x1 + x2.
struct NeedleDims {
  double l1_m;       // crank OA on the main shaft
  double l2_m;       // coupler AB
  double l3_m;       // rocker CB
  double l4_m;       // arm CD, rigid with l3
  double l5_m;       // connecting rod DE
  double l6_m;       // needle bar from its pin E down to the needle point F
  double x1_m;       // |OO'|: horizontal offset of C from O
  double h1_m;       // |O'C|: vertical offset of C from O
  double x2_m;       // |O'O''|: horizontal offset of the needle line from C
  double beta1_rad;  // fixed angle between l3 and l4: θ4 = θ3 + β1 - 2π (002 eqn 15)
};

// Configure-time only. 002 Table 1 (DHGN801D-400) with β1 = 168°.
NeedleDims needle_table1();

// Assembly branch of the crank-rocker, defined exactly as the side of the rocker pin B relative to the
// directed line C -> A (right or left of it). With 002's layout (the needle line to the right of C)
// the right side puts B on the side of the line O-C away from the needle bar: kPinAwayFromNeedle, the
// paper's eqns 7-8 (θ3 = 3π/2 - φ1 - φ3); with Table 1 only that one reaches the needle at all.
enum class NeedleRockerSide { kPinAwayFromNeedle, kPinTowardNeedle };
// Assembly branch of the rocker-slider: the rod D-E hangs from the arm's end D down to the needle
// bar's pin E (sin θ5 < 0, θ5 in the third quadrant where cos θ5 < 0): 002's Fig. 2 and the meaning of
// eqn 14 (the needle below D). kStandingRod is its mirror image (E above D, the principal value of
// eqn 14's acos taken literally): the same loop equations, but a different machine.
enum class NeedleRodSide { kHangingRod, kStandingRod };

// RT-safe. Short physical names for CSV and messages ("away"/"toward", "hanging"/"standing").
const char* needle_rocker_side_name(NeedleRockerSide s);
const char* needle_rod_side_name(NeedleRodSide s);

struct NeedleBranch {
  NeedleRockerSide rocker = NeedleRockerSide::kPinAwayFromNeedle;
  NeedleRodSide rod = NeedleRodSide::kHangingRod;
};

// One instant of the mechanism. θ_i is the direction of link l_i (from x, counter-clockwise):
// θ1 of O->A, θ2 of A->B, θ3 of C->B, θ4 of C->D, θ5 of D->E. ω = dθ/dt, α = d²θ/dt² (002 calls it a).
struct NeedleState {
  double theta1_rad, theta2_rad, theta3_rad, theta4_rad, theta5_rad;
  double omega1_rad_s, omega2_rad_s, omega3_rad_s, omega4_rad_s, omega5_rad_s;
  double alpha1_rad_s2, alpha2_rad_s2, alpha3_rad_s2, alpha4_rad_s2, alpha5_rad_s2;
  double needle_m;       // l_CF' = l6 - l4 sin θ4 - l5 sin θ5: depth of the needle point F below C
  double needle_v_m_s;   // d(l_CF')/dt (positive = needle going down)
  double needle_a_m_s2;  // d²(l_CF')/dt²
};

class NeedleLinkage {
 public:
  // Configure-time only. Validates the dimensions: throws MotionError kInvalidInput (non-finite or
  // non-positive length), kNotCrank (l1 cannot turn fully in a crank-rocker), kSingular (change-point
  // four-bar, or the rod reaches a toggle within the rocker swing), kNotAssemblable (the rod l5
  // cannot reach the needle line somewhere in the swing). After that, evaluate() cannot fail.
  explicit NeedleLinkage(const NeedleDims& dims, NeedleBranch branch = {});

  // RT-safe. Positions, velocities and accelerations at main-shaft angle θ1, speed ω1, accel α1.
  // Angles are principal values (θ2, θ5 in (-π, π], θ3 in [0, 2π), θ4 = θ3 + β1 - 2π).
  NeedleState evaluate(double theta1_rad, double omega1_rad_s, double alpha1_rad_s2 = 0.0) const;

  // RT-safe. Largest absolute residual (m) of the three scalar loop equations (002 eqn 1 and the
  // horizontal part of eqn 14) at a state: how far the computed pose is from closing.
  double closure_residual_m(const NeedleState& s) const;

  // θ3 at the two dead centres of the crank-rocker (crank and coupler collinear, extended and
  // folded), found from the triangle O-B-C alone: the limits of the rocker swing, in [0, 2π).
  struct RockerLimits {
    double extended_rad;
    double folded_rad;
  };
  // RT-safe accessors.
  RockerLimits rocker_limits() const { return limits_; }
  const NeedleDims& dims() const { return d_; }
  NeedleBranch branch() const { return branch_; }

 private:
  NeedleDims d_;
  NeedleBranch branch_;
  RockerLimits limits_{};
};

// Configure-time only (allocates). One main-shaft turn, θ1 = 2π·i/samples, at constant ω1; every
// angle after the first sample is unwrapped against the previous one, so each column is continuous.
// Throws MotionError kInvalidInput for samples < 1 or a non-finite ω1.
std::vector<NeedleState> needle_sweep(const NeedleLinkage& linkage, int samples, double omega1_rad_s);
// Configure-time only. The same sweep handed to `sink` one state at a time, in constant memory.
void needle_sweep(const NeedleLinkage& linkage, int samples, double omega1_rad_s,
                  const std::function<void(const NeedleState&)>& sink);

}  // namespace loom::motion
