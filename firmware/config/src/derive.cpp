// The derivation: every module's config (the profile spec, the sequencer's, the simulator's) from the
// machine, recipe and run settings, once; the crank speed from the beat-force target through the
// linkage's inverse dynamics.
#include "derive.hpp"

#include <algorithm>
#include <cmath>

#include "drives.hpp"
#include "loom/drivers/can_axis_config.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/mass_properties.hpp"
#include "loom/motion/profile_crank.hpp"

namespace loom::firmware {
namespace detail {

double beat_speed_ratio(const LoomConfig& c) {
  const Recipe& rc = c.recipe;
  if (rc.crank_law.kind == motion::CrankLawKind::kConstant) return 1.0;
  const motion::BeatUp head(c.machine_spec.beatup);
  const double fell_phase = head.warp().fell;
  const motion::CrankLaw speed_law(
      rc.crank_law, fell_phase,
      {.size = rc.table_size, .interp = rc.table_interp, .precision = rc.table_precision, .rise = 0.0});
  double x = fell_phase;  // Newton on Φc(x) = x + offset(x) = fell; dΦc/dx ≥ min ratio > 0
  for (int i = 0; i < 50; ++i) {
    const motion::CrankLawExact e = speed_law.exact(x);
    const double step = (x + e.offset - fell_phase) / e.d1;
    x -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return speed_law.exact(x).d1;
}

namespace {

// A selector's cruise speed: its max_speed, and with a drive no faster than the speed at which the drive's
// torque-speed line still gives the recipe's selector acceleration to the rotor and gears alone (J a ≤ τp
// (1 − ω/ω0)): the point-to-point move's box lies inside the drive's envelope. (The magazine's own
// inertia is not described; check_axis_drives refuses an acceleration the rotor alone cannot take.)
double selector_top_speed(const LoomConfig& c, const AxisSpec& a) {
  const DriveModel* m = a.drive.empty() ? nullptr : find_drive(c, a.drive);
  if (m == nullptr) return a.max_speed;
  const motion::ServoDrive& d = m->drive;
  const double room =
      1.0 - d.output_inertia_kg_m2() * c.knotting.selector_accel_rad_s2 / d.output_peak_torque_nm();
  return std::min(a.max_speed, d.output_speed_rad_s() * std::max(room, 0.0));
}

// Crank (master) speed for the recipe: given, or from the beat-force target through the linkage's
// inverse dynamics (the beater force is inertial, so it scales with ω²) and the crank law.
double master_crank_speed(const LoomConfig& c, const Fail& fail) {
  const Recipe& rc = c.recipe;
  if (rc.beat_force_target_n <= 0.0) return rc.crank_speed_rad_s;
  const auto& m = c.machine_spec;
  double crank_speed_at_beat = 0.0;
  try {
    const motion::BeatUpDynamics dyn(m.beatup, motion::beatup_masses(m.beatup, m.beater_mass_kg));
    crank_speed_at_beat = dyn.crank_speed_for_beat_force(rc.beat_force_target_n);
  } catch (const motion::MotionError& e) {
    fail("recipe.beat_force_target_n", fmt_num(rc.beat_force_target_n), e.what());
  }
  // With a speed law the crank is faster (or slower) than the master at the beat: the master runs at
  // the crank speed divided by the law's ratio where the crank reaches the fell.
  const double master = crank_speed_at_beat / beat_speed_ratio(c);
  if (!std::isfinite(master) || master < 0.1 || master > 100.0) {
    fail("recipe.beat_force_target_n", fmt_num(rc.beat_force_target_n),
         "needs a crank speed of " + fmt_num(master) + " rad/s, outside the crank's [0.1, 100] rad/s");
  }
  return master;
}

}  // namespace

void derive(LoomConfig& c, const Fail& fail) {
  const MachineSpec& m = c.machine_spec;
  const Recipe& rc = c.recipe;
  c.beat_force_target_n = rc.beat_force_target_n > 0.0 ? rc.beat_force_target_n : 0.0;

  motion::ProfileSpec& p = c.profile;
  p = motion::ProfileSpec{};
  p.beatup = m.beatup;
  p.width_m = m.width_m;
  p.beater_width_m = m.beater_width_m;
  p.overlap_m = rc.overlap_m;
  p.beats_per_position = rc.beats_per_position;
  p.crank = {.velocity = 0.0, .acceleration = rc.crank_accel_rad_s2, .jerk = rc.crank_jerk_rad_s3};
  p.crank_law = rc.crank_law;
  p.cam_margin_rad = rc.cam_margin_rad;
  p.carriage_max_speed_m_s = m.carriage_max_speed_m_s;
  p.carriage_max_accel_m_s2 = m.carriage_max_accel_m_s2;
  p.carriage_max_jerk_m_s3 = m.carriage_max_jerk_m_s3;
  p.helix_lead_m = m.helix_lead_m;
  p.helix = m.helix;
  p.carrier_force_n = m.carrier_force_n;
  p.shuttle_mass_kg = m.shuttle_mass_kg;
  p.shed = m.shed;
  p.table_size = rc.table_size;
  p.table_interp = rc.table_interp;
  p.table_precision = rc.table_precision;
  p.max_table_error_rad = rc.max_table_error_rad;
  p.crank.velocity = master_crank_speed(c, fail);

  LoopTiming& t = c.timing;
  t.period_s = c.run.period_s;
  t.period_ns = static_cast<std::int64_t>(std::llround(t.period_s * 1e9));
  t.can_diagnosis_window_s = c.can.heartbeat_timeout_ms * 1e-3 + 10.0 * t.period_s;

  sequencer::SequencerConfig& s = c.sequencer;
  s = sequencer::SequencerConfig{};
  s.period_s = t.period_s;
  s.axes = axis_layout(c);
  for (std::size_t i = hal::kCoreAxisCount; i < c.axes.size(); ++i) s.axis_max_speed[i] = c.axes[i].max_speed;
  for (std::size_t i = 0; i < c.axes.size(); ++i)
    s.homing_timeout_s[i] = c.axes[i].homing ? c.axes[i].homing_timeout_s : 0.0;
  s.picks_per_row = rc.picks_per_row;
  s.knotting = c.knotting.mode == sequencer::KnottingMode::kWeaver;
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    // Head h drives with the h-th knotter and the h-th selector axis in slot order (names sort: knotter_1,
    // knotter_2, ...). The design program and the knot cycle are built with the machine (they need the
    // design's progress); the selectors' top speed is their axes' max_speed.
    sequencer::KnottingConfig& k = s.heads;
    int knotters = 0, selectors = 0;
    double selector_speed = 1e300;
    for (std::size_t i = hal::kCoreAxisCount; i < c.axes.size(); ++i) {
      if (c.axes[i].role == hal::AxisRole::kKnotter && knotters < sequencer::kMaxKnottingHeads) {
        k.knotter_axis[static_cast<std::size_t>(knotters++)] = static_cast<int>(i);
      } else if (c.axes[i].role == hal::AxisRole::kSelector && selectors < sequencer::kMaxKnottingHeads) {
        k.selector_axis[static_cast<std::size_t>(selectors++)] = static_cast<int>(i);
        selector_speed = std::min(selector_speed, selector_top_speed(c, c.axes[i]));
      }
    }
    k.take_position_rad = c.knotting.take_position_rad;
    k.selector_zero_rad = c.knotting.selector_zero_rad;
    k.placement_tolerance_m = sequencer::placement_tolerance_m(c.knotting);
    if (selectors > 0) {
      k.selector = {.velocity = selector_speed,
                    .acceleration = c.knotting.selector_accel_rad_s2,
                    .jerk = c.knotting.selector_jerk_rad_s3};
    }
    // Selectors in profile position: their drive's profile starts a tick or two after the plan's and is
    // reported on change, at most once per TPDO inhibit time; they may be measured that much later.
    bool profile_selectors = false;
    for (const AxisSpec& a : c.axes)
      profile_selectors |= a.role == hal::AxisRole::kSelector && a.profile_position;
    if (profile_selectors) {
      k.selector_settle_s =
          k.settle_s + drivers::CanAxisPortConfig{}.profile_tpdo_inhibit_s + 2.0 * t.period_s;
    }
  }
  s.debounce_ticks = c.run.debounce_ticks;
  s.sensor_discrepancy_s = c.run.sensor_discrepancy_s;
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i)
    s.second_channel[i] = c.io.wiring.second[i].bit >= 0;
  s.enable_timeout_s = c.run.enable_timeout_s;
  s.pick_timeout_margin_s = c.run.pick_timeout_margin_s;
  s.row_save_timeout_s = c.run.row_save_timeout_s;
  s.stale_timeout_s = c.run.stale_timeout_s;
  s.crank_park_position_rad = m.calibration.crank_park_position_rad;
  s.carriage_home_m = m.calibration.carriage_home_m;
  s.helix_left_position_rad = m.calibration.helix_left_position_rad;
  s.beat_force_min_n = rc.beat_force_min_n;
  s.beat_force_max_n = rc.beat_force_max_n;
  s.carriage = {.velocity = m.carriage_max_speed_m_s,
                .acceleration = m.carriage_max_accel_m_s2,
                .jerk = m.carriage_reposition_jerk_m_s3};

  sim_hal::SimMachine& sm = c.machine;
  sm = sim_hal::SimMachine{};
  sm.period_s = t.period_s;
  sm.axis_count = c.axes.size();
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const AxisSpec& a = c.axes[i];
    if (!a.homing) continue;
    sm.referencing[i] = {.method = a.homing_method,
                         .home_offset = a.home_offset,
                         .speed = a.homing_speed,
                         .index_pitch = hal::is_rotary(a.role) ? 2.0 * M_PI : a.lead_m};
  }
  sm.width_m = m.width_m;
  sm.beater_width_m = m.beater_width_m;  // where across the width the comb beats (warp_tension)
  sm.carriage_home_m = m.calibration.carriage_home_m;
  sm.helix_lead_m = m.helix_lead_m;
  sm.piston_travel_s = m.shed.piston_travel_s;
  sm.beatup = m.beatup;
  sm.crank_park_position_rad = m.calibration.crank_park_position_rad;
  sm.second_channel = s.second_channel;
}

}  // namespace detail

void derive_module_configs(LoomConfig& c) {
  detail::derive(c, [&](const std::string& key, const std::string& value, const std::string& why) {
    throw ConfigError(c.source + ": " + key + " = " + value + ": " + why);
  });
}

}  // namespace loom::firmware
