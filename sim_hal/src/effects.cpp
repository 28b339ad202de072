// Axis effects.
#include "loom/sim_hal/effects.hpp"

#include <algorithm>
#include <cmath>

#include "loom/motion/dynamics.hpp"
#include "loom/motion/forward_dynamics.hpp"
#include "loom/motion/mass_properties.hpp"

namespace loom::sim_hal {
namespace {

class ServoLagEffect final : public AxisEffect {
 public:
  explicit ServoLagEffect(const ServoLag& p) : tau_(p.tau_s) {}
  double step(double target, double actual, double dt) noexcept override {
    // The decay factor depends only on dt; cache it so a tick costs one multiply-add.
    if (dt != dt_) {
      dt_ = dt;
      alpha_ = tau_ > 0.0 ? 1.0 - std::exp(-dt / tau_) : 1.0;
    }
    return actual + alpha_ * (target - actual);
  }

 private:
  double tau_;
  double dt_ = -1.0;
  double alpha_ = 1.0;
};

class CrankInertiaEffect final : public AxisEffect {
 public:
  CrankInertiaEffect(const SimMachine& m, const Inertia& p, const JointFriction* f)
      : p_(p),
        dynamics_(m.beatup, motion::beatup_masses(m.beatup, p.beater_mass_kg)),
        model_(dynamics_, 2048, {}, f ? f->viscous_nm_s : 0.0, p.drive_inertia_kg_m2),
        coulomb_(f ? f->coulomb_nm : 0.0),
        offset_(motion::BeatUp(m.beatup).park_crank_angle() - m.crank_park_position_rad) {}

  double step(double target, double actual, double dt) noexcept override {
    if (!primed_) {
      state_ = {actual + offset_, 0.0};
      prev_target_ = target;
      primed_ = true;
    }
    // The drive interpolates linearly between CSP targets and closes a PD loop on it, scaled by the
    // linkage's own inertia at the present angle (a well-tuned drive's inertia feed-forward).
    const double wn = 2.0 * 3.14159265358979323846 * p_.bandwidth_hz;
    const double v_target = (target - prev_target_) / dt;
    const int n = std::max(1, p_.substeps);
    const double h = dt / n;
    for (int i = 0; i < n; ++i) {
      const double frac = static_cast<double>(i + 1) / n;
      const double goal = prev_target_ + frac * (target - prev_target_) + offset_;
      const double m_eff = model_.terms(state_.theta_rad).inertia_kg_m2;
      const double pd =
          m_eff * (wn * wn * (goal - state_.theta_rad) + 2.0 * wn * (v_target - state_.omega_rad_s));
      const double tau = std::clamp(pd, -p_.motor_torque_limit_nm, p_.motor_torque_limit_nm);
      const double friction = -coulomb_ * std::tanh(state_.omega_rad_s / 1e-3);
      state_ = motion::step_rk4(model_, state_, h, motion::StepTorque::hold(tau + friction));
    }
    prev_target_ = target;
    return state_.theta_rad - offset_;
  }

 private:
  Inertia p_;
  motion::BeatUpDynamics dynamics_;
  motion::BeatUpForwardModel model_;
  double coulomb_;
  double offset_;
  motion::CrankState state_{};
  double prev_target_ = 0.0;
  bool primed_ = false;
};

}  // namespace

std::unique_ptr<AxisEffect> make_crank_inertia(const SimMachine& machine, const Inertia& p,
                                               const JointFriction* friction) {
  return std::make_unique<CrankInertiaEffect>(machine, p, friction);
}

std::unique_ptr<AxisEffect> make_servo_lag(const ServoLag& p) {
  return std::make_unique<ServoLagEffect>(p);
}

}  // namespace loom::sim_hal
