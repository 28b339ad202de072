// Builds and checks the profile set. Every check that can fail names the numbers a loom builder needs
// to change, because a profile that silently breaks a limit is worse than no profile.
#include "loom/motion/profile_set.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {
namespace {

[[noreturn]] void infeasible(const std::ostringstream& os) { throw MotionError(ErrorCode::kInvalidInput, os.str()); }

int beats_for(const ProfileSpec& s) {
  const double pitch = s.beater_width_m - s.overlap_m;
  if (!(s.width_m > 0) || !(s.beater_width_m > 0) || !(s.overlap_m >= 0) || !(pitch > 0) ||
      s.beater_width_m > s.width_m) {
    std::ostringstream os;
    os << "width " << s.width_m << " m, beater width " << s.beater_width_m << " m and overlap " << s.overlap_m
       << " m need 0 < overlap < beater width <= width";
    infeasible(os);
  }
  return static_cast<int>(std::ceil((s.width_m - s.beater_width_m) / pitch - 1e-9)) + 1;
}

}  // namespace

ProfileSet::ProfileSet(const ProfileSpec& spec)
    : spec_(spec),
      beatup_(spec.beatup),
      rocker_(spec.table_size,
              [this](double p) {
                const BeaterState s = beatup_.at(p);
                return PhaseTable::Exact{s.rocker_angle, s.d1};
              }),
      beats_(beats_for(spec)) {
  validate(spec.crank, "beat-up crank");
  validate(spec.helix, "helix shaft");
  // Equal pitch from selvedge to selvedge: never more than the nominal pitch, so overlap is kept.
  const double travel = carriage_travel_m();
  const double pitch = beats_ > 1 ? travel / (beats_ - 1) : spec.beater_width_m - spec.overlap_m;
  cam_ = CarriageCam(beatup_.warp(), spec.cam_margin_rad, pitch, beats_ - 1);

  sweep_ = JerkMove::plan(kTwoPi * beats_, spec.crank);
  const WarpWindow& w = beatup_.warp();
  if (sweep_.ramp_distance() > w.enter || sweep_.ramp_distance() > kTwoPi - w.exit ||
      sweep_.peak_velocity() < spec.crank.velocity) {
    std::ostringstream os;
    os << "beat-up crank cannot reach " << spec.crank.velocity << " rad/s before the first beat: run-up needs "
       << deg(sweep_.ramp_distance()) << " deg, the beater enters the warp " << deg(w.enter)
       << " deg after park and leaves it " << deg(kTwoPi - w.exit)
       << " deg before park; raise crank acceleration/jerk or lower the speed";
    infeasible(os);
  }
  // Carriage limits at cruise crank speed: the smooth step's peak s' = 35/16, peak |s''| = 84√5/25 ≈ 7.51.
  const double omega = spec.crank.velocity;
  const double v_peak = cam_.pitch() * (35.0 / 16.0) / cam_.window_length() * omega;
  const double a_peak = cam_.pitch() * 7.5132 / (cam_.window_length() * cam_.window_length()) * omega * omega;
  if (v_peak > spec.carriage_max_speed_m_s || a_peak > spec.carriage_max_accel_m_s2) {
    std::ostringstream os;
    os << "carriage step of " << cam_.pitch() << " m in a " << deg(cam_.window_length()) << " deg clear window at "
       << omega << " rad/s needs " << v_peak << " m/s and " << a_peak << " m/s^2; limits are "
       << spec.carriage_max_speed_m_s << " m/s and " << spec.carriage_max_accel_m_s2
       << " m/s^2 (lower the crank speed or the pitch, or widen the clear window)";
    infeasible(os);
  }

  // The carrier drags the shuttle magnetically: shuttle acceleration must stay below F/m.
  if (!(spec.helix_lead_m > 0) || !(spec.carrier_force_n > 0) || !(spec.shuttle_mass_kg > 0)) {
    std::ostringstream os;
    os << "helix lead " << spec.helix_lead_m << " m, carrier force " << spec.carrier_force_n
       << " N and shuttle mass " << spec.shuttle_mass_kg << " kg must all be positive";
    infeasible(os);
  }
  const double carrier_limit = spec.carrier_force_n / spec.shuttle_mass_kg * kTwoPi / spec.helix_lead_m;
  JerkLimits helix = spec.helix;
  helix.acceleration = std::min(helix.acceleration, carrier_limit);
  helix_accel_ = helix.acceleration;
  pick_ = JerkMove::plan(kTwoPi * spec.width_m / spec.helix_lead_m, helix);
  pick_back_ = JerkMove::plan(-kTwoPi * spec.width_m / spec.helix_lead_m, helix);
}

}  // namespace loom::motion
