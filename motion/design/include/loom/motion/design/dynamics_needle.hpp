// Inverse dynamics of the tufting-needle six-bar (seed 002): the two linear systems A·F = B (crank
// l1, coupler l2, rocker l3) and C·F = D (arm l4, rod l5, needle bar l6) re-derived from Newton–Euler
// with one sign convention throughout, 002 Table 1 masses and inertias, gravity, and the needle's
// friction with the backing (1000 N in 002) reversing with the needle's direction. C·F = D is solved
// first: its weld torque M_r between l4 and l3 is a load on l3 in A·F = B. Configure-time only.
//
// Where this derivation differs from the printed paper (typos, not physics): eqn 23 uses l2 for the
// crank pin A's acceleration (it is l1), eqn 33 has ω4 where ω4² belongs, eqn 30 prints ten columns
// for nine unknowns and eqn 31 names one of them F_R_l2-l2 (it is l3 on l2), eqn 41 prints nine
// columns for eight unknowns, and M_r enters the moment equations of l3 (eqn 28) and l4 (eqn 35) with
// the same sign, which would break action–reaction; here l3 receives −M_r.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "loom/motion/design/needle.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/dynamics_body.hpp"

namespace loom::motion {

// Masses and central moments of inertia of l1..l6; centres at mid-length (002 eqns 20–36). l6, the
// needle bar, only translates: its inertia never enters.
struct NeedleMasses {
  std::array<double, 6> mass_kg{};
  std::array<double, 6> inertia_kg_m2{};
};
// Configure-time only. 002 Table 1 (DHGN801D-400, cast steel).
NeedleMasses needle_table1_masses();

struct NeedleLoads {
  double friction_n = 1000.0;  // backing friction on the needle, against its motion (002: 1000 N)
  Eigen::Vector2d gravity_m_s2{0.0, -kStandardGravity_m_s2};  // needle frame: y up
};

// The two systems at one instant, as assembled (moment rows and torque unknowns divided by
// length_scale_m so that the matrices are dimensionless).
//   A·x = B, x = (F_21, F_O1, F_32, F_C3, M_b/L): forces on l1 from l2 at A, from the frame at O,
//            on l2 from l3 at B, on l3 from the frame at C, and the balancing torque on l1.
//   C·y = D, y = (F_C4, F_54, F_65, N, M_r/L): forces on l4 at C, on l4 from l5 at D, on l5 from l6
//            at E, the guide's horizontal force on l6, and the weld torque l3 puts on l4.
struct NeedleSystems {
  Eigen::Matrix<double, 9, 9> A;
  Eigen::Matrix<double, 9, 1> B;
  Eigen::Matrix<double, 8, 8> C;
  Eigen::Matrix<double, 8, 1> D;
  double length_scale_m = 1.0;
};

struct NeedleForces {
  NeedleState state;
  double friction_n = 0.0;  // signed: the backing's vertical force on the needle bar
  Eigen::Vector2d pin_a_n = Eigen::Vector2d::Zero();   // l2 on l1 at A
  Eigen::Vector2d pin_o_n = Eigen::Vector2d::Zero();   // frame on l1 at O (main shaft bearing)
  Eigen::Vector2d pin_b_n = Eigen::Vector2d::Zero();   // l3 on l2 at B
  Eigen::Vector2d pin_c3_n = Eigen::Vector2d::Zero();  // frame on l3 at C
  Eigen::Vector2d pin_c4_n = Eigen::Vector2d::Zero();  // frame on l4 at C
  Eigen::Vector2d pin_d_n = Eigen::Vector2d::Zero();   // l5 on l4 at D
  Eigen::Vector2d pin_e_n = Eigen::Vector2d::Zero();   // l6 on l5 at E
  double guide_n = 0.0;                                // guide on the needle bar, horizontal
  double weld_torque_nm = 0.0;                         // M_r: l3 on l4 through the rigid joint at C
  double balancing_torque_nm = 0.0;                    // M_b: torque the main shaft must apply to l1
  // Total frame reaction at the rocker pivot C (l3 and l4 share it).
  Eigen::Vector2d pin_c_n() const { return pin_c3_n + pin_c4_n; }
};

// RT-safe. Motion of the six links (l6's frame: origin at E, never rotating) at a solved state.
std::array<BodyMotion, 6> needle_motion(const NeedleLinkage& linkage, const NeedleState& s);
// Configure-time only. The six bodies in their link frames (centres at mid-length; l6's below E).
std::array<PlanarInertia, 6> needle_bodies(const NeedleLinkage& linkage, const NeedleMasses& m);

// Configure-time only. Assemble the two systems. Throws kInvalidInput for non-finite/negative masses
// or loads.
NeedleSystems needle_systems(const NeedleLinkage& linkage, const NeedleMasses& m, const NeedleState& s,
                             const NeedleLoads& loads = {});
// Configure-time only. Solve them. Throws kSingular if either system is singular.
NeedleForces needle_inverse_dynamics(const NeedleLinkage& linkage, const NeedleMasses& m,
                                     const NeedleState& s, const NeedleLoads& loads = {});
// Configure-time only (allocates). One main-shaft turn at constant ω1, θ1 = 2πi/samples.
std::vector<NeedleForces> needle_dynamics_sweep(const NeedleLinkage& linkage, const NeedleMasses& m,
                                                int samples, double omega1_rad_s,
                                                const NeedleLoads& loads = {});

}  // namespace loom::motion
