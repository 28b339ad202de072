// The core axes against their drives (see loom/config/core_drives.hpp and drives.hpp).
#include "loom/config/core_drives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "drives.hpp"
#include "keys.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/sequencer/beat_regulator.hpp"

namespace loom::firmware {

using detail::fmt_num;

namespace {

constexpr int kLinkageSamples = 360;  // a degree of crank apart: the torque's peak to well under 1 %

std::string figure(double v) {  // 3 significant digits, as a person reads a data sheet
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

// The beat-up linkage's load on the crank at its fastest speed: the inverse dynamics' crank torque over a
// turn at that constant speed (the links' and beater's inertia and weight; the beat force is the
// beater's own inertia, so it is in it), its peak and its rms (the crank turns through every beat).
void linkage_load(const LoomConfig& c, CoreDriveFit& f) {
  const MachineSpec& m = c.machine_spec;
  try {
    const motion::BeatUpDynamics dyn(m.beatup, motion::beatup_masses(m.beatup, m.beater_mass_kg));
    double peak = 0.0, sum_sq = 0.0;
    const std::vector<motion::BeatUpSample> turn = dyn.sweep(f.need_speed, kLinkageSamples);
    for (const motion::BeatUpSample& s : turn) {
      peak = std::max(peak, std::abs(s.forces.crank_torque_nm));
      sum_sq += s.forces.crank_torque_nm * s.forces.crank_torque_nm;
    }
    f.load_effort = peak;
    f.load_rms_effort = std::sqrt(sum_sq / static_cast<double>(turn.size()));
    f.load_effort_what = "the linkage " + figure(peak) + " N m (its peak over a turn at that speed)";
  } catch (const motion::MotionError& e) {
    f.load_effort = f.load_rms_effort = std::numeric_limits<double>::quiet_NaN();
    f.load_effort_what = std::string("the linkage (its load could not be computed: ") + e.what() + ")";
  }
}

}  // namespace

DriveAtAxis drive_at_axis(const motion::ServoDrive& d, const AxisSpec& a) {
  DriveAtAxis at{.top_speed = d.output_speed_rad_s(),
                 .peak_effort = d.output_peak_torque_nm(),
                 .rated_effort = d.output_rated_torque_nm(),
                 .inertia = d.output_inertia_kg_m2()};
  if (hal::is_rotary(a.role)) return at;
  const double m_per_rad = d.gear_ratio * a.lead_m / (2.0 * M_PI);  // travel per output radian
  at.top_speed *= m_per_rad;
  at.peak_effort /= m_per_rad;
  at.rated_effort /= m_per_rad;
  at.inertia /= m_per_rad * m_per_rad;
  return at;
}

std::vector<CoreDriveFit> core_drive_fits(const LoomConfig& c, const motion::ProfileSet& set) {
  std::vector<CoreDriveFit> out;
  for (const AxisSpec& a : c.axes) {
    if (a.drive.empty()) continue;
    const DriveModel* m = detail::find_drive(c, a.drive);
    if (m == nullptr) continue;  // refused when the axes were read
    CoreDriveFit f;
    f.axis = a.name;
    f.model = m->name;
    f.role = a.role;
    f.at = drive_at_axis(m->drive, a);
    switch (a.role) {
      case hal::AxisRole::kBeatCrank: {
        // The fastest the crank turns: the master speed, times the crank law's fastest ratio, times the
        // beat regulator's top speed scale (it may beat that much faster than the recipe).
        const bool from_force = c.recipe.beat_force_target_n > 0.0;
        const sequencer::BeatRegulatorConfig& reg = c.sequencer.beat_regulator;
        const double scale = reg.enabled ? std::max(1.0, reg.max_speed_scale) : 1.0;
        const double law = set.crank_law().max_ratio();
        f.need_speed = c.profile.crank.velocity * law * scale;
        f.speed_key = from_force ? "recipe.beat_force_target_n" : "recipe.crank_speed_rad_s";
        f.speed_value = fmt_num(from_force ? c.recipe.beat_force_target_n : c.recipe.crank_speed_rad_s);
        f.speed_what = "the crank at " + figure(c.profile.crank.velocity) + " rad/s" +
                       (from_force ? " (for the beat force)" : "") +
                       (law > 1.0 ? " x the crank law's fastest ratio " + figure(law) : "") +
                       (scale > 1.0 ? " x the beat regulator's top scale " + figure(scale) : "");
        f.need_accel = c.profile.crank.acceleration;
        f.accel_key = "recipe.crank_accel_rad_s2";
        f.accel_value = fmt_num(c.recipe.crank_accel_rad_s2);
        linkage_load(c, f);
        break;
      }
      case hal::AxisRole::kCarriage:
        // Its re-arm moves cruise at the limit; the cam's steps stay within it (checked with the cam).
        f.need_speed = c.machine_spec.carriage_max_speed_m_s;
        f.speed_key = "carriage.max_speed_m_s";
        f.speed_value = fmt_num(f.need_speed);
        f.speed_what = "the carriage's re-arm moves cruise at it; its cam steps peak at " +
                       figure(set.carriage_peaks().speed_m_s) + " m/s";
        f.need_accel = c.machine_spec.carriage_max_accel_m_s2;
        f.accel_key = "carriage.max_accel_m_s2";
        f.accel_value = fmt_num(f.need_accel);
        f.load_inertia = c.machine_spec.carriage_mass_kg;
        f.load_what = "the carriage's " + figure(f.load_inertia) + " kg (carriage.mass_kg)";
        f.load_key = "carriage.mass_kg";
        f.load_value = fmt_num(f.load_inertia);
        break;
      case hal::AxisRole::kHelix: {
        f.need_speed = set.helix_limits().velocity;
        f.speed_key = "helix.max_speed_rad_s";
        f.speed_value = fmt_num(c.machine_spec.helix.velocity);
        f.speed_what = "the pick peaks at " + figure(std::abs(set.pick().peak_velocity())) + " rad/s";
        f.need_accel = set.helix_accel_limit();  // after the carrier's limit
        f.accel_key = "helix.max_accel_rad_s2";
        f.accel_value = fmt_num(c.machine_spec.helix.acceleration);
        const double r = c.machine_spec.helix_lead_m / (2.0 * M_PI);
        f.load_inertia = c.machine_spec.shuttle_mass_kg * r * r;
        f.load_what = "the shuttle";
        f.load_key = "helix.shuttle_mass_kg";
        f.load_value = fmt_num(c.machine_spec.shuttle_mass_kg);
        break;
      }
      default:
        continue;  // added axes: their max_speed is checked against the drive (check_axis_drives)
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::string effort_parts(const CoreDriveFit& f, const char* effort) {
  std::string parts = "the drive's own rotor and gears";
  if (!f.load_what.empty()) parts += " and " + f.load_what;
  parts += " at " + figure(f.need_accel) + (hal::is_rotary(f.role) ? " rad/s^2: " : " m/s^2: ") +
           figure((f.at.inertia + f.load_inertia) * f.need_accel) + " " + effort;
  if (!f.load_effort_what.empty()) parts += "; " + f.load_effort_what;
  return parts;
}

namespace detail {

void check_core_drives(const LoomConfig& c, const motion::ProfileSet& set, const Fail& fail) {
  for (const CoreDriveFit& f : core_drive_fits(c, set)) {
    const DriveModel& m = *find_drive(c, f.model);
    const bool rotary = hal::is_rotary(f.role);
    const char* unit = rotary ? "rad/s" : "m/s";
    const std::string drive = "the drive " + f.model + " (axes." + f.axis + ".drive)";
    // Said at the key that asks, else at the line naming the drive (a file that only changes the drive).
    const std::string named = "axes." + f.axis + ".drive";
    const std::string rpm = fmt_num(m.drive.motor_speed_rad_s * 60.0 / (2.0 * M_PI));
    if (f.need_speed > f.at.top_speed * (1.0 + 1e-12)) {
      fail(f.speed_key + "|" + named, f.speed_value + "|\"" + f.model + "\"",
           "needs " + figure(f.need_speed) + " " + unit + " (" + f.speed_what + "); " + drive + " gives " +
               figure(f.at.top_speed) + " " + unit + " at the output (" + rpm + " rpm / gear_ratio " +
               fmt_num(m.drive.gear_ratio) +
               (rotary ? std::string()
                       : " x lead " + fmt_num(c.axes[hal::index(hal::CoreAxis::kCarriage)].lead_m) + " m") +
               ")");
    }
    const char* effort = rotary ? "N m" : "N";
    if (!(f.need_effort() <= f.line_effort())) {
      // The speed takes the line's share that the load then lacks: when the load alone is over the line,
      // the speed (or the load) is what to lower, else the acceleration.
      const bool speed_binds = !(f.load_effort < f.line_effort());
      const std::string load_key = f.load_key.empty() ? "" : f.load_key + "|";
      const std::string load_value = f.load_key.empty() ? "" : f.load_value + "|";
      fail((speed_binds ? f.speed_key : f.accel_key) + "|" + load_key + named,
           (speed_binds ? f.speed_value : f.accel_value) + "|" + load_value + "\"" + f.model + "\"",
           "needs " + figure(f.need_effort()) + " " + effort + " at " + figure(f.need_speed) + " " + unit +
               " (" + effort_parts(f, effort) + "); " + drive + " gives " + figure(f.line_effort()) + " " +
               effort + " there (its torque-speed line: " + figure(f.at.peak_effort) + " " + effort +
               " at standstill, 0 at its no-load " + figure(f.at.top_speed) + " " + unit + ")");
    } else if (!(f.load_rms_effort <= f.at.rated_effort)) {
      fail(f.speed_key + "|" + named, f.speed_value + "|\"" + f.model + "\"",
           "needs " + figure(f.load_rms_effort) + " " + effort + " rms over a turn at " +
               figure(f.need_speed) + " " + unit + " for the linkage; " + drive + " gives " +
               figure(f.at.rated_effort) + " " + effort + " continuously");
    }
  }
}

}  // namespace detail

}  // namespace loom::firmware
