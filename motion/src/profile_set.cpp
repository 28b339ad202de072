// Builds and checks the profile set. Every check that can fail names the numbers a loom builder needs
// to change, because a profile that silently breaks a limit is worse than no profile.
#include "loom/motion/profile_set.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {
namespace {

[[noreturn]] void infeasible(const std::ostringstream& os) {
  throw MotionError(ErrorCode::kInvalidInput, os.str());
}

int beats_for(const ProfileSpec& s) {
  const double pitch = s.beater_width_m - s.overlap_m;
  if (!(s.width_m > 0) || !(s.beater_width_m > 0) || !(s.overlap_m >= 0) || !(pitch > 0) ||
      s.beater_width_m > s.width_m) {
    std::ostringstream os;
    os << "width " << s.width_m << " m, beater width " << s.beater_width_m << " m and overlap " << s.overlap_m
       << " m need 0 <= overlap < beater width <= width";
    infeasible(os);
  }
  return static_cast<int>(std::ceil((s.width_m - s.beater_width_m) / pitch - 1e-9)) + 1;
}

// Worst |table − exact| at the segment midpoints, where every Hermite order's error peaks.
template <class Exact>
double midpoint_error(const PhaseTable& t, const Exact& exact) {
  double worst = 0.0;
  const std::size_t n = t.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Phase mid = Phase::from_turns((static_cast<double>(i) + 0.5) / static_cast<double>(n));
    worst = std::max(worst, std::abs(t.at(mid).value - exact(mid.frac_rad())));
  }
  return worst;
}

TableSpec table_spec(const ProfileSpec& s) {
  return {.size = s.table_size, .interp = s.table_interp, .precision = s.table_precision, .rise = 0.0};
}

}  // namespace

ProfileSet::ProfileSet(const ProfileSpec& spec)
    : spec_(spec),
      beatup_(spec.beatup),
      rocker_(table_spec(spec),
              [this](double p) {
                const BeaterState s = beatup_.at(p);
                return PhaseExact{s.rocker_angle, s.d1, s.d2};
              }),
      crank_law_(spec.crank_law, beatup_.warp().fell, table_spec(spec)),
      beats_(beats_for(spec)) {
  validate(spec.crank, "beat-up crank");
  validate(spec.helix, "helix shaft");
  validate(spec.shed);
  rocker_error_ = midpoint_error(rocker_, [this](double p) { return beatup_.at(p).rocker_angle; });
  crank_error_ = midpoint_error(crank_law_.table(), [this](double p) { return crank_law_.exact(p).offset; });
  if (!(rocker_error_ <= spec.max_table_error_rad) || !(crank_error_ <= spec.max_table_error_rad)) {
    std::ostringstream os;
    os << spec.table_size << "-knot " << interp_name(spec.table_interp) << " "
       << precision_name(spec.table_precision) << " tables miss the exact kinematics by up to "
       << std::max(rocker_error_, crank_error_) << " rad (rocker " << rocker_error_ << ", crank law "
       << crank_error_ << "), more than profiles.max_table_error_rad = " << spec.max_table_error_rad
       << "; raise profiles.table_size or use profiles.interp = \"quintic\" (float32 knots stop near 3e-8 "
          "rad)";
    infeasible(os);
  }
  // Equal pitch from selvedge to selvedge: never more than the nominal pitch, so overlap is kept.
  // beats_for() counts carriage positions; each is beaten beats_per_position times.
  if (spec.beats_per_position < 1 || spec.beats_per_position > 16) {
    std::ostringstream os;
    os << "beats per carriage position must be in [1, 16], got " << spec.beats_per_position;
    infeasible(os);
  }
  const int positions = beats_;
  const double travel = carriage_travel_m();
  const double pitch = positions > 1 ? travel / (positions - 1) : spec.beater_width_m - spec.overlap_m;
  cam_ = CarriageCam(beatup_.warp(), spec.cam_margin_rad, pitch, positions - 1, spec.beats_per_position);
  beats_ = positions * spec.beats_per_position;

  // The master runs up to speed before the crank reaches the warp and brakes after it left it for the
  // last time; the crank law moves where the crank is at those master phases.
  sweep_ = JerkMove::plan(kTwoPi * beats_, spec.crank);
  const WarpWindow& w = beatup_.warp();
  const double ramp = sweep_.ramp_distance();
  const double crank_at_speed = ramp + crank_law_.exact(ramp).offset;
  const double crank_braking = kTwoPi - ramp + crank_law_.exact(-ramp).offset;
  if (crank_at_speed > w.enter || crank_braking < w.exit || sweep_.peak_velocity() < spec.crank.velocity) {
    std::ostringstream os;
    os << "beat-up crank cannot reach " << spec.crank.velocity
       << " rad/s before the first beat: run-up needs " << deg(ramp) << " deg of master phase (crank at "
       << deg(crank_at_speed) << " deg), the beater enters the warp " << deg(w.enter)
       << " deg after park and leaves it " << deg(kTwoPi - w.exit)
       << " deg before park; raise recipe.crank_accel_rad_s2 / recipe.crank_jerk_rad_s3 or lower "
          "recipe.crank_speed_rad_s";
    infeasible(os);
  }
  carriage_peaks_ = check_carriage_step(cam_, crank_law_, spec.crank.velocity,
                                        {.speed_m_s = spec.carriage_max_speed_m_s,
                                         .accel_m_s2 = spec.carriage_max_accel_m_s2,
                                         .jerk_m_s3 = spec.carriage_max_jerk_m_s3});

  // The carrier drags the shuttle magnetically: shuttle acceleration must stay below F/m.
  if (!(spec.helix_lead_m > 0) || !(spec.carrier_force_n > 0) || !(spec.shuttle_mass_kg > 0)) {
    std::ostringstream os;
    os << "helix lead " << spec.helix_lead_m << " m, carrier force " << spec.carrier_force_n
       << " N and shuttle mass " << spec.shuttle_mass_kg << " kg must all be positive";
    infeasible(os);
  }
  const double carrier_limit = spec.carrier_force_n / spec.shuttle_mass_kg * kTwoPi / spec.helix_lead_m;
  helix_ = spec.helix;
  helix_.acceleration = std::min(helix_.acceleration, carrier_limit);
  pick_ = JerkMove::plan(kTwoPi * spec.width_m / spec.helix_lead_m, helix_);
  pick_back_ = JerkMove::plan(-kTwoPi * spec.width_m / spec.helix_lead_m, helix_);
}

PhaseSample ProfileSet::rocker_at(const Phase& master) const noexcept {
  const PhaseSample offset = crank_law_.table().at(master);
  const PhaseSample r = rocker_.at(master.plus_small_rad(offset.value));
  const double c1 = 1.0 + offset.d1;
  return {r.value, r.d1 * c1, r.d2 * c1 * c1 + r.d1 * offset.d2};
}

}  // namespace loom::motion
