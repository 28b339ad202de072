// Tabulated reduced model of the beat-up. M and V are stored with their exact slopes, and the lookup
// returns the interpolant's own derivative, so the equation integrated is the Lagrangian of the
// tabulated M and V — a conservative system in its own right.
#include "loom/motion/forward_dynamics.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

// Returns `samples` once every input is known good, so the table members can be built in order.
std::size_t validated(std::size_t samples, const BeatContact& contact, double viscous, double drive) {
  std::ostringstream os;
  if (samples < 4) {
    os << "forward model: table samples = " << samples << ": must be >= 4";
  } else if (!(contact.force_n >= 0.0) || !std::isfinite(contact.force_n)) {
    os << "forward model: contact force = " << contact.force_n << " N: must be finite and >= 0";
  } else if (!(viscous >= 0.0) || !std::isfinite(viscous)) {
    os << "forward model: viscous friction = " << viscous << " N m s/rad: must be finite and >= 0";
  } else if (!(drive >= 0.0) || !std::isfinite(drive)) {
    os << "forward model: drive inertia = " << drive << " kg m^2: must be finite and >= 0";
  } else {
    return samples;
  }
  throw MotionError(ErrorCode::kInvalidInput, os.str());
}

}  // namespace

BeatUpForwardModel::BeatUpForwardModel(const BeatUpDynamics& d, std::size_t samples,
                                       const BeatContact& contact, double viscous, double drive_inertia)
    : inertia_(validated(samples, contact, viscous, drive_inertia),
               [&](double th) {
                 const ReducedTerms t = d.reduced(th);
                 return PhaseTable::Exact{t.inertia_kg_m2, t.dinertia_kg_m2_rad};
               }),
      potential_(samples,
                 [&](double th) {
                   return PhaseTable::Exact{d.potential_energy(th), d.reduced(th).gravity_torque_nm};
                 }),
      rocker_(samples,
              [&](double th) {
                const BeatUpGeometry& g = d.head().geometry();
                const FourBarPose p = solve(g.bar, th, g.branch);
                return PhaseTable::Exact{wrap_pi(p.theta4 - d.fell_rocker_angle()), p.k4};
              }),
      fell_theta4_(d.fell_rocker_angle()),
      away_sign_(d.away_from_fell_sign()),
      warp_depth_m_(d.head().geometry().warp_depth_m),
      arm_m_(d.head().geometry().beater_arm_m),
      lever_m_(d.masses().beater_at_m.norm()),
      contact_n_(contact.force_n),
      viscous_(viscous),
      drive_inertia_(drive_inertia) {}

ReducedTerms BeatUpForwardModel::terms(double theta) const noexcept {
  const PhaseSample m = inertia_.at(theta);
  ReducedTerms t;
  t.inertia_kg_m2 = m.value + drive_inertia_;
  t.dinertia_kg_m2_rad = m.d1;
  t.gravity_torque_nm = potential_.at(theta).d1;
  return t;
}

double BeatUpForwardModel::potential_j(double theta) const noexcept {
  return potential_.at(theta).value;
}

double BeatUpForwardModel::external_torque_nm(const CrankState& s) const noexcept {
  double q = -viscous_ * s.omega_rad_s;
  if (contact_n_ > 0.0) {
    const PhaseSample r = rocker_.at(s.theta_rad);  // θ4 − θ4(fell), continuous
    const bool in_warp = arm_m_ * std::abs(r.value) < warp_depth_m_;
    const bool advancing = away_sign_ * r.d1 * s.omega_rad_s < 0.0;
    if (in_warp && advancing) q += contact_n_ * away_sign_ * lever_m_ * r.d1;
  }
  return q;
}

double BeatUpForwardModel::acceleration(const CrankState& s, double torque_nm) const noexcept {
  const ReducedTerms t = terms(s.theta_rad);
  return (torque_nm + external_torque_nm(s) - 0.5 * t.dinertia_kg_m2_rad * s.omega_rad_s * s.omega_rad_s -
          t.gravity_torque_nm) /
         t.inertia_kg_m2;
}

double BeatUpForwardModel::energy_j(const CrankState& s) const noexcept {
  return 0.5 * (inertia_.at(s.theta_rad).value + drive_inertia_) * s.omega_rad_s * s.omega_rad_s +
         potential_j(s.theta_rad);
}

double BeatUpExactForwardModel::acceleration(const CrankState& s, double torque_nm) const {
  const ReducedTerms t = d_->reduced(s.theta_rad);
  const double q =
      d_->contact_generalized_force({s.theta_rad, s.omega_rad_s, 0.0}, contact_) - viscous_ * s.omega_rad_s;
  return (torque_nm + q - 0.5 * t.dinertia_kg_m2_rad * s.omega_rad_s * s.omega_rad_s - t.gravity_torque_nm) /
         (t.inertia_kg_m2 + drive_inertia_);
}

double BeatUpExactForwardModel::energy_j(const CrankState& s) const {
  return d_->kinetic_energy({s.theta_rad, s.omega_rad_s, 0.0}) +
         0.5 * drive_inertia_ * s.omega_rad_s * s.omega_rad_s + d_->potential_energy(s.theta_rad);
}

}  // namespace loom::motion
