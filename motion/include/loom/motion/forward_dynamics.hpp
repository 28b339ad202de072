// Forward dynamics of the beat-up for the simulator: the crank angle θ is the one coordinate, the motor
// torque τ the input, and M(θ)θ̈ + ½M'(θ)θ̇² + dV/dθ = τ + Q_cloth − c·θ̇ the equation of motion.
// The tabulated model is built at configure time and evaluated RT-safe; M' and dV/dθ are the exact
// derivatives of the tabulated M and V, so the discrete model conserves its own energy exactly (an
// integrator's drift is then the integrator's alone). Two integrators: classic RK4 and semi-implicit
// Euler. The free linkage is fast — the 2.5 kg beater swings M(θ) ninefold within a turn — so steps of
// 10–100 µs are needed for energy errors of 1e-8–1e-6 (see the benchmark). The cloth force is one-sided
// (it resists the advance only); a crank that stalls inside the warp makes it chatter, so drive the
// crank through the beat, as the servo does.
#pragma once

#include <cstddef>

#include "loom/motion/dynamics.hpp"
#include "loom/motion/phase_table.hpp"

namespace loom::motion {

struct CrankState {
  double theta_rad = 0.0;
  double omega_rad_s = 0.0;
};

// The motor torque over one step, sampled where RK4 needs it. A servo's zero-order hold is hold(τ).
struct StepTorque {
  double start_nm = 0.0, mid_nm = 0.0, end_nm = 0.0;
  static constexpr StepTorque hold(double nm) { return {nm, nm, nm}; }
};

class BeatUpForwardModel {
 public:
  // Configure-time only. Tabulates M(θ), V(θ) and the rocker angle at `samples` crank angles (cubic
  // Hermite with exact slopes). viscous_nm_s is a crank bearing's viscous friction (N·m·s/rad);
  // drive_inertia_kg_m2 the motor, gears and any flywheel reflected to the crank (added to M).
  // Throws MotionError(kInvalidInput) for samples < 4, negative/non-finite friction, inertia or force.
  explicit BeatUpForwardModel(const BeatUpDynamics& d, std::size_t samples = 4096,
                              const BeatContact& contact = {}, double viscous_nm_s = 0.0,
                              double drive_inertia_kg_m2 = 0.0);

  // RT-safe. Reduced-model terms at crank angle θ (any real).
  ReducedTerms terms(double theta_rad) const noexcept;
  double potential_j(double theta_rad) const noexcept;
  // RT-safe. Generalised forces besides the motor: the cloth (while the beater advances through the
  // warp) and bearing friction.
  double external_torque_nm(const CrankState& s) const noexcept;
  // RT-safe. θ̈ under motor torque τ.
  double acceleration(const CrankState& s, double torque_nm) const noexcept;
  // RT-safe. Mechanical energy ½M(θ)θ̇² + V(θ) of the tabulated model (J).
  double energy_j(const CrankState& s) const noexcept;

  // RT-safe accessor.
  std::size_t samples() const noexcept { return inertia_.size(); }

 private:
  PhaseTable inertia_;
  PhaseTable potential_;
  PhaseTable rocker_;  // θ4 measured continuously from the fell pose; slope ∂θ4/∂θ
  double fell_theta4_ = 0.0;
  double away_sign_ = 1.0;
  double warp_depth_m_ = 0.0;
  double arm_m_ = 0.0;    // beater arm used for the warp test (BeatUp's definition)
  double lever_m_ = 0.0;  // distance of the contact point from B0
  double contact_n_ = 0.0;
  double viscous_ = 0.0;
  double drive_inertia_ = 0.0;
};

// The same model evaluated exactly through the linkage solve: the reference that tables and
// integrators are measured against. Configure-time only (the linkage solve may throw).
class BeatUpExactForwardModel {
 public:
  // Configure-time only; keeps a reference to `d`, which must outlive the model.
  explicit BeatUpExactForwardModel(const BeatUpDynamics& d, const BeatContact& contact = {},
                                   double viscous_nm_s = 0.0, double drive_inertia_kg_m2 = 0.0)
      : d_(&d), contact_(contact), viscous_(viscous_nm_s), drive_inertia_(drive_inertia_kg_m2) {}
  // Configure-time only. As BeatUpForwardModel's, evaluated exactly.
  double acceleration(const CrankState& s, double torque_nm) const;
  double energy_j(const CrankState& s) const;

 private:
  const BeatUpDynamics* d_;
  BeatContact contact_;
  double viscous_;
  double drive_inertia_;
};

// One classic fourth-order Runge–Kutta step. RT-safe when Model::acceleration is.
template <class Model>
CrankState step_rk4(const Model& m, const CrankState& s, double dt, const StepTorque& tau) {
  const double k1t = s.omega_rad_s;
  const double k1w = m.acceleration(s, tau.start_nm);
  const CrankState s2{s.theta_rad + 0.5 * dt * k1t, s.omega_rad_s + 0.5 * dt * k1w};
  const double k2t = s2.omega_rad_s;
  const double k2w = m.acceleration(s2, tau.mid_nm);
  const CrankState s3{s.theta_rad + 0.5 * dt * k2t, s.omega_rad_s + 0.5 * dt * k2w};
  const double k3t = s3.omega_rad_s;
  const double k3w = m.acceleration(s3, tau.mid_nm);
  const CrankState s4{s.theta_rad + dt * k3t, s.omega_rad_s + dt * k3w};
  const double k4t = s4.omega_rad_s;
  const double k4w = m.acceleration(s4, tau.end_nm);
  return {s.theta_rad + dt / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t),
          s.omega_rad_s + dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w)};
}

// One semi-implicit Euler step: speed first, then angle with the new speed. First order and one
// evaluation per step; symplectic for separable systems, which this one (½M'θ̇² depends on both θ and
// θ̇) is not, so its energy error is measured rather than assumed bounded. RT-safe when
// Model::acceleration is.
template <class Model>
CrankState step_semi_implicit_euler(const Model& m, const CrankState& s, double dt, double torque_nm) {
  const double w = s.omega_rad_s + dt * m.acceleration(s, torque_nm);
  return {s.theta_rad + dt * w, w};
}

}  // namespace loom::motion
