// Inverse dynamics of the beat-up four-bar: Newton–Euler for crank, coupler and rocker (with the
// beater) assembled as one 9×9 Eigen system — four pin forces and the crank torque — at any crank
// angle, speed and acceleration, gravity on, plus an optional cloth contact force on the beater. Also
// the reduced (one-coordinate) model M(θ), M'(θ), dV/dθ that forward dynamics integrates, and the crank
// speed that gives a chosen peak beat force. Configure-time/offline analysis: functions may throw
// MotionError (kSingular at a toggle, kInvalidInput for non-finite inputs), never return NaN.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/motion/dynamics_body.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/mass_properties.hpp"

namespace loom::motion {

inline constexpr double kStandardGravity_m_s2 = 9.80665;

// The crank's angle, speed and acceleration at one instant (any speed law is a sequence of these).
struct CrankMotion {
  double theta_rad = 0.0;
  double omega_rad_s = 0.0;
  double alpha_rad_s2 = 0.0;
};

// RT-safe. Motion of the crank, coupler and rocker link frames (see BeatUpMasses for the frames) from
// a solved pose and the crank's speed and acceleration.
std::array<BodyMotion, 3> four_bar_motion(const FourBar& m, const FourBarPose& pose, double omega2_rad_s,
                                          double alpha2_rad_s2);

// Mass properties of the three moving links, each in its own link frame.
struct FourBarInertias {
  PlanarInertia crank, coupler, rocker;
};

// An external force on the rocker at a point of the rocker frame (the cloth pushing on the beater).
struct RockerLoad {
  Eigen::Vector2d force_n = Eigen::Vector2d::Zero();
  Eigen::Vector2d at_m = Eigen::Vector2d::Zero();
};

// Pin forces, each the force the named pin applies to the second-named (downstream) link, world frame.
struct FourBarForces {
  Eigen::Vector2d pin_a0_n = Eigen::Vector2d::Zero();  // ground on crank at A0
  Eigen::Vector2d pin_a_n = Eigen::Vector2d::Zero();   // crank on coupler at A
  Eigen::Vector2d pin_b_n = Eigen::Vector2d::Zero();   // coupler on rocker at B
  Eigen::Vector2d pin_b0_n = Eigen::Vector2d::Zero();  // ground on rocker at B0
  double crank_torque_nm = 0.0;                        // motor on crank, + counter-clockwise
  double rcond = 0.0;  // reciprocal condition estimate of the (dimensionless) 9×9 system
};

// Below this reciprocal condition the 9×9 system is treated as singular.
inline constexpr double kSingularRcond = 1e-12;

// Configure-time only. Solves the Newton–Euler system at one pose. Throws MotionError: kInvalidInput
// for non-finite speed/acceleration/gravity/load, kSingular when the system is singular (coupler and
// rocker in line: no pin force can hold the rocker's moment).
FourBarForces four_bar_forces(const FourBar& m, const FourBarInertias& inertias, const FourBarPose& pose,
                              double omega2_rad_s, double alpha2_rad_s2, const Eigen::Vector2d& gravity_m_s2,
                              const RockerLoad& load = {});

// The cloth's resistance: while the beater advances through the warp toward the fell, the cloth
// pushes back on its tip with this force, along the tip's path. Zero while it retreats (compaction is
// not given back), so over a turn the crank does force × warp depth of work on the cloth.
struct BeatContact {
  double force_n = 0.0;
};

// One instant of the beat-up under inverse dynamics.
struct BeatUpSample {
  CrankMotion crank;
  double phase_rad = 0.0;  // from the park pose (BeatUp's phase)
  Eigen::Vector2d tip_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d tip_vel_m_s = Eigen::Vector2d::Zero();
  Eigen::Vector2d tip_acc_m_s2 = Eigen::Vector2d::Zero();
  double tip_acc_abs_m_s2 = 0.0;
  double beater_force_n = 0.0;  // beater mass × |tip acceleration|: the thesis' "force on the beater"
  Eigen::Vector2d contact_force_n = Eigen::Vector2d::Zero();  // cloth on the beater tip
  FourBarForces forces;
  double transmission_rad = 0.0;
  bool in_warp = false;
  bool near_toggle = false;  // transmission angle within Options::near_toggle_rad of 0 or π
};

// The one-coordinate model with the crank angle θ as generalised coordinate:
// M(θ)θ̈ + ½M'(θ)θ̇² + dV/dθ = τ + Q.
struct ReducedTerms {
  double inertia_kg_m2 = 0.0;       // M = Σ m|∂r_G/∂θ|² + I(∂φ/∂θ)²
  double dinertia_kg_m2_rad = 0.0;  // M' = dM/dθ
  double gravity_torque_nm = 0.0;   // dV/dθ = −Σ m g·∂r_G/∂θ
};

// Largest beater force while the teeth are in the warp, at constant crank speed.
struct BeatForcePeak {
  double omega_rad_s = 0.0;
  double force_n = 0.0;           // peak of beater_force_n inside the warp window
  double crank_rad = 0.0;         // θ2 where it occurs
  double fell_force_n = 0.0;      // at the fell dead centre (the thesis' "bottom position")
  double turn_max_force_n = 0.0;  // largest over the whole turn (may lie outside the window)
  double turn_max_crank_rad = 0.0;
};

class BeatUpDynamics {
 public:
  struct Options {
    Eigen::Vector2d gravity_m_s2{0.0, -kStandardGravity_m_s2};  // in the linkage frame (A0→B0 = +x)
    double near_toggle_rad = rad(15.0);
  };

  // Configure-time only. Throws what BeatUp throws, and kInvalidInput for bad masses/options.
  BeatUpDynamics(const BeatUpGeometry& g, const BeatUpMasses& m, const Options& o);
  BeatUpDynamics(const BeatUpGeometry& g, const BeatUpMasses& m) : BeatUpDynamics(g, m, Options{}) {}

  // Configure-time only. Full inverse dynamics at one instant.
  BeatUpSample inverse(const CrankMotion& c, const BeatContact& contact = {}) const;
  // Configure-time only (allocates). θ2 = 2πi/samples, constant speed. Throws kInvalidInput on
  // samples < 1 or non-finite ω.
  std::vector<BeatUpSample> sweep(double omega_rad_s, int samples, const BeatContact& contact = {}) const;

  // Configure-time only (each solves the linkage). Link motions; kinetic and potential energy; the
  // cloth's force on the beater tip at this instant (zero outside the advance through the warp).
  std::array<BodyMotion, 3> motion(const CrankMotion& c) const;
  double kinetic_energy(const CrankMotion& c) const;
  double potential_energy(double theta2_rad) const;
  Eigen::Vector2d contact_force(const CrankMotion& c, const BeatContact& contact) const;

  // Configure-time only. Exact reduced-model terms at θ2 (from the kinematic coefficients, not from
  // the pin-force solve) and the cloth's generalised force Q = F·∂r_tip/∂θ.
  ReducedTerms reduced(double theta2_rad) const;
  double contact_generalized_force(const CrankMotion& c, const BeatContact& contact) const;

  // Configure-time only. Peak beat force at constant speed (sampled, then refined by golden section).
  // With the default geometry and the crank turning counter-clockwise the peak comes about 18° of
  // crank after the fell, as the beater leaves; the thesis saw it just before the fell. At constant
  // speed the accelerations are the same with time reversed, so turning the crank the other way puts
  // the same peak on the approach.
  BeatForcePeak peak_beat_force(double omega_rad_s) const;
  // Configure-time only. The constant crank speed whose in-warp peak beater force equals target_n.
  // The beater force is purely inertial, so it scales exactly with ω²; throws kInvalidInput for a
  // non-positive target.
  double crank_speed_for_beat_force(double target_n) const;

  // RT-safe accessors. bodies(): crank, coupler, rocker + beater, each in its link frame.
  const std::array<PlanarInertia, 3>& bodies() const { return bodies_; }
  const BeatUp& head() const { return head_; }
  const BeatUpMasses& masses() const { return masses_; }
  const Options& options() const { return opt_; }
  // Sign of θ4 − θ4(fell) over the whole swing: +1 or −1 (the rocker never crosses the fell pose).
  double away_from_fell_sign() const { return away_sign_; }
  double fell_rocker_angle() const { return fell_theta4_; }

 private:
  BeatUp head_;
  BeatUpMasses masses_;
  Options opt_;
  FourBarInertias inertias_;
  std::array<PlanarInertia, 3> bodies_;
  double fell_theta4_ = 0.0;
  double away_sign_ = 1.0;
};

}  // namespace loom::motion
