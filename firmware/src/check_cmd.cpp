// `loomctl check`: the plan a loom builder wants to see before anything moves — everything derived
// from the machine description, computed by the same code the loop and the CAN master use.
#include "check_cmd.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "loom/config/config.hpp"
#include "loom/config/core_drives.hpp"
#include "loom/config/eds_nodes.hpp"
#include "loom/config/scene_config.hpp"
#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/required_objects.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/knot_cycle.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/sequencer/beat_regulator.hpp"
#include "loom/sequencer/row_time.hpp"
#include "loom/sim_hal/effects.hpp"
#include "loom/sim_heads/sim_heads.hpp"

namespace loom::firmware {
namespace {

void print_keys() {
  std::printf("%-36s %-8s %s\n", "key", "class", "range");
  for (const KeyInfo& k : config_keys()) std::printf("%-36s %-8s %s\n", k.path, k.klass, k.range.c_str());
}

std::string io_module_signals(const IoModuleSpec& m) {
  std::string out;
  for (const std::string& s : m.signals) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// "io" for the [io] table's module, "io_modules.<name>" for a further one.
std::string module_key(const LoomConfig& c, std::uint8_t module) {
  return module == 0 ? std::string("io") : "io_modules." + c.io.modules[module - 1u].name;
}

// An input's bit, with its module when the loom has several.
std::string input_at(const LoomConfig& c, const drivers::IoBit& b) {
  return std::to_string(b.bit) + (c.io.modules.empty() ? "" : " (" + module_key(c, b.module) + ")");
}

// Which safety sensors have a second switch, where both are wired, and what a sensor without one
// cannot catch.
void print_safety_sensors(const LoomConfig& c) {
  std::printf("\nsafety sensors\n");
  const drivers::IoWiring& w = c.io.wiring;
  const auto first = drivers::first_switches(w);
  std::string dual, single;
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    const std::string name = hal::safety_sensor_name(static_cast<hal::SafetySensor>(i));
    if (c.sequencer.second_channel[i]) {
      dual +=
          "    " + name + ": inputs " + input_at(c, *first[i]) + " and " + input_at(c, w.second[i]) + "\n";
    } else {
      single += (single.empty() ? "" : ", ") + name;
    }
  }
  if (!dual.empty()) {
    std::printf(
        "  two switches each, acted on only while both agree; apart longer than %.0f ms (after the %d-tick "
        "debounce) is the fault sensor_discrepancy:\n%s",
        c.sequencer.sensor_discrepancy_s * 1e3, c.sequencer.debounce_ticks, dual.c_str());
  }
  if (!single.empty()) {
    std::printf(
        "  WARNING single switch (io.<sensor>_2_bit = -1): %s. A stuck switch there that meets a second "
        "fault (a shuttle slipped off its carrier, a piston seized mid-stroke) reads as the healthy machine "
        "would: a frame can close on the shuttle or a pick run through a half-open shed.\n",
        single.c_str());
  }
}

// The configured axes: slot, name, role, drive node, scaling and supervision, one line each.
void print_axes(const LoomConfig& c, const motion::ProfileSet& set) {
  std::printf("\naxes (%zu of at most %zu)\n", c.axes.size(), hal::kMaxAxes);
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const AxisSpec& a = c.axes[i];
    const char* unit = hal::axis_unit(a.role);
    char speed[64] = "", ferror[96] = "not supervised by the controller";
    if (a.max_speed > 0.0) std::snprintf(speed, sizeof speed, ", top speed %g %s/s", a.max_speed, unit);
    if (a.ferror_min > 0.0)
      std::snprintf(ferror, sizeof ferror, "> max(%g %s, %g s x |v|)", a.ferror_min, unit, a.ferror_k_s);
    // A profile-position drive runs each move's ramp itself: the controller supervises its set-point
    // acknowledge and "target reached" (drivers/README.md), not a following error against a ramp it sent.
    if (a.profile_position) {
      std::snprintf(ferror, sizeof ferror, "%s", "not used: profile position, one set-point a move");
    }
    std::printf("  %zu %-12s %-10s bus %u node %3u  %.0f counts/%s%s; following error %s\n", i,
                a.name.c_str(), hal::axis_role_name(a.role), a.bus, a.node, a.counts_per_unit(), unit, speed,
                ferror);
  }
  // The core axes' drives: what each gives at the axis, what the motion asks, and which limit binds (the
  // mechanism's key while it asks less than the drive gives; the config refuses more).
  const std::vector<CoreDriveFit> fits = core_drive_fits(c, set);
  if (!fits.empty())
    std::printf(
        "  core axes' drives (at the axis; the carriage's through its lead, travel per motor turn):\n");
  for (const CoreDriveFit& f : fits) {
    const bool rotary = hal::is_rotary(f.role);
    const char* speed = rotary ? "rad/s" : "m/s";
    const char* effort = rotary ? "N m" : "N";
    std::printf(
        "    %-12s drives.%s: no-load %.3g %s, peak %.4g %s, continuous %.4g %s, rotor and gears %.3g %s\n",
        f.axis.c_str(), f.model.c_str(), f.at.top_speed, speed, f.at.peak_effort, effort, f.at.rated_effort,
        effort, f.at.inertia, rotary ? "kg m^2" : "kg");
    std::printf("      speed: %s asks %.3g %s, %.0f %% of the drive's no-load speed; binding: the key\n",
                f.speed_key.c_str(), f.need_speed, speed, 100.0 * f.need_speed / f.at.top_speed);
    // The config refuses a file whose need is over the line, so what is printed here fits.
    std::printf(
        "      effort at that speed, accelerating at %s: %.3g %s (%s), %.0f %% of the %.3g %s its "
        "torque-speed line gives there\n",
        f.accel_key.c_str(), f.need_effort(), effort, effort_parts(f, effort).c_str(),
        100.0 * f.need_effort() / f.line_effort(), f.line_effort(), effort);
    if (f.load_rms_effort > 0.0) {
      std::printf("      continuous: the linkage's %.3g %s rms over a turn, %.0f %% of the drive's %.4g %s\n",
                  f.load_rms_effort, effort, 100.0 * f.load_rms_effort / f.at.rated_effort, f.at.rated_effort,
                  effort);
    }
  }
  // Referencing: what the loom does with each axis after its drive powers up, in the order it arms.
  std::printf(
      "  referencing (at every arming, in this order; an unreferenced axis never moves in production):\n");
  int step = 0;
  for (const AxisSpec& a : c.axes) {
    const char* unit = hal::axis_unit(a.role);
    if (!a.homing) continue;
    const char* how = a.homing_method == 19   ? "home switch, active on its positive side"
                      : a.homing_method == 21 ? "home switch, active on its negative side"
                      : a.homing_method == 33 ? "index pulse, negative direction"
                      : a.homing_method == 34 ? "index pulse, positive direction"
                                              : "where it stands";
    std::printf(
        "    %d. %s: CiA 402 homing method %d (%s) at %g %s/s, reads %g %s at the home point; fault "
        "homing_failed after %g s%s\n",
        ++step, a.name.c_str(), a.homing_method, how, a.homing_speed, unit, a.home_offset, unit,
        a.homing_timeout_s,
        a.role == hal::AxisRole::kCarriage ? " (only once the beater is clear of the warp)" : "");
  }
  std::string absolute;
  for (const AxisSpec& a : c.axes) {
    if (!a.homing) absolute += (absolute.empty() ? "" : ", ") + a.name;
  }
  if (!absolute.empty()) {
    std::printf("    absolute (positions known from power-up; references set by loomctl commission): %s\n",
                absolute.c_str());
  }
}

// The heads' time per row. With a design: rows 1 and 2 tied by the heads' own sequence against an ideal
// plant (sequencer/row_time.hpp), so every wait counts — a carriage step or selector turn that outlasts the
// gripper's return, the settles, the first travel and the way to the sweep's start; the design's rows differ,
// so their mean. Without a design (nothing to tie): the knot cycles alone.
struct KnotRowTime {
  int cycles = 0;
  double cycles_s = 0.0;                 // the knot cycles back to back
  std::optional<double> row1_s, row2_s;  // design rows 1 and 2 (each knotted from the left selvedge)
  double mean_s() const { return row1_s && row2_s ? (*row1_s + *row2_s) / 2.0 : cycles_s; }
};

KnotRowTime knot_row_time(const LoomConfig& c, const motion::KnotCycle& cycle, double carriage_travel_m) {
  KnotRowTime t;
  t.cycles = std::min(sequencer::knots_per_stripe(c.knotting),
                      sequencer::knots_per_row(c.knotting, c.machine_spec.width_m));
  t.cycles_s = t.cycles * cycle.duration_s();
  if (!c.recipe.design) return t;
  const KnottingHeads heads = build_heads(c, 0, 0);
  sequencer::SequencerConfig s = c.sequencer;
  s.heads.program = heads.program.get();
  s.heads.cycle = heads.cycle.get();
  const double period = c.sequencer.period_s;
  const auto limit = static_cast<hal::Tick>((t.cycles_s * 10.0 + 600.0) / period);
  const auto seconds_of = [&](std::uint32_t row0) -> std::optional<double> {
    const auto ticks = sequencer::ideal_row_knotting_ticks(s, carriage_travel_m, row0, limit);
    if (!ticks) return std::nullopt;
    return static_cast<double>(*ticks) * period;
  };
  t.row1_s = seconds_of(0);
  t.row2_s = seconds_of(1);
  return t;
}

// The knot plan: density and carpet class, and with knotting heads how a row is tied — knots per head,
// knot cycles and carriage steps per row, and the design's selector moves.
void print_knotting(const LoomConfig& c, const std::optional<motion::KnotCycle>& knot_cycle,
                    const KnotRowTime& row_time) {
  const sequencer::KnottingSpec& k = c.knotting;
  const double density = k.knots_per_dm * k.rows_per_dm;
  std::printf("\nknotting: %s", sequencer::knotting_mode_name(k.mode));
  if (k.mode == sequencer::KnottingMode::kNone) {
    std::printf(" (a flat weave: no pile knots)\n");
    return;
  }
  std::printf(", %s knot, %g knots/dm x %g rows/dm = %g knots/dm^2 (%s)\n", sequencer::knot_type_name(k.knot),
              k.knots_per_dm, k.rows_per_dm, density,
              sequencer::carpet_class_name(sequencer::carpet_class(density)));
  const int per_row = sequencer::knots_per_row(k, c.machine_spec.width_m);
  std::printf("  %d knots per row over %.3f m (pitch %.2f mm)\n", per_row, c.machine_spec.width_m,
              sequencer::knot_pitch_m(k) * 1e3);
  if (k.mode == sequencer::KnottingMode::kWeaver) {
    std::printf("  the weaver knots each row by hand while the loom waits (pedal or ctl next)\n");
    return;
  }
  const int stripe = sequencer::knots_per_stripe(k);
  std::printf(
      "  %d heads %.3f m apart, each tying a stripe of up to %d knots: %d knot cycles and %d carriage steps "
      "of one pitch per row\n",
      k.heads, k.head_spacing_m, stripe, std::min(stripe, per_row),
      std::max(0, std::min(stripe, per_row) - 1));
  // Knot placement: the tolerance the heads use (given, or derived from the pitch) and how long a carriage
  // may take to be measured there (the heads' settle time and the feedback's allowed age).
  const sequencer::KnottingConfig& heads = c.sequencer.heads;
  const double tol = sequencer::placement_tolerance_m(k);
  std::printf(
      "  a knot cycle starts with the carriage measured within %.3f mm of its knot (%s); not there %.0f ms "
      "after its step: carriage_not_at_knot\n",
      tol * 1e3, k.placement_tolerance_m > 0.0 ? "knotting.placement_tolerance_m" : "a quarter of the pitch",
      sequencer::carriage_arrival_s(heads, c.sequencer.stale_timeout_s) * 1e3);
  // The knot cycle: built (and checked) from the linkage and the servo's limits.
  const motion::KnotCycle& cycle = *knot_cycle;  // built (and checked) once, in print_plan
  const motion::KnotCycleReport& rep = cycle.report();
  std::printf(
      "  knot cycle %.3f s through seed 001's linkage (%s, servo %s): TAKE %.1f deg, WRAP %.1f deg, PULL "
      "%.1f deg "
      "(crank); least transmission angle %.1f deg\n",
      cycle.duration_s(), motion::grashof_class_name(rep.grashof),
      rep.full_turn ? "turns on round" : "swings back", motion::deg(rep.crank_angles_rad[0]),
      motion::deg(rep.crank_angles_rad[1]), motion::deg(rep.crank_angles_rad[2]),
      motion::deg(rep.min_transmission_rad));
  std::printf("   ");
  for (const auto& seg : rep.segments) {
    std::printf(" %s %.3f s (%s)", seg.name, seg.end_s - seg.begin_s, motion::knot_limit_name(seg.bound));
  }
  // Which limit binds: the speed cap where a move cruises at it, else the drive's torque-speed line (every
  // move drives on it and brakes at the peak); the continuous torque as the cycle's rms share of it.
  const motion::KnotCycleSpec& ks = c.knot_cycle;
  bool capped = false;
  for (const auto& seg : rep.segments) capped |= seg.bound == motion::KnotLimit::kSpeedCap;
  std::string drive = "the embedded default's";
  for (const AxisSpec& a : c.axes) {
    if (a.role == hal::AxisRole::kKnotter && !a.drive.empty()) {
      drive = "drives." + a.drive + " (axes." + a.name + ".drive)";
      break;
    }
  }
  char cap[32] = "none";
  if (ks.max_speed_rad_s > 0.0) std::snprintf(cap, sizeof cap, "%.3g rad/s", ks.max_speed_rad_s);
  std::printf(
      "\n    servo at the output, %s: no-load %.3g rad/s, peak %.3g N m, continuous %.3g N m, rotor and "
      "gears "
      "%.3g kg m^2; speed cap %s\n",
      drive.c_str(), ks.no_load_speed_rad_s, ks.peak_torque_nm, ks.continuous_torque_nm,
      ks.rotor_inertia_kg_m2, cap);
  std::printf(
      "    binding: %s; fastest %.3g rad/s (%.0f %% of no-load), peak torque %.3g N m at %.3f s, rms torque "
      "%.3g N m (%.0f %% of the continuous)\n",
      capped ? "the speed cap (a knotter axis' max_speed below its drive's)"
             : "the torque-speed line (each move drives on it and brakes at the peak torque)",
      rep.peak_speed_rad_s, 100.0 * rep.peak_speed_rad_s / ks.no_load_speed_rad_s,
      std::abs(rep.peak_torque_nm), rep.peak_torque_t_s, rep.rms_torque_nm,
      100.0 * rep.rms_torque_nm / ks.continuous_torque_nm);
  std::printf(
      "    gripper in the warp %.3f..%.3f s, cutter %.3f..%.3f s, yarn-present sampled %.3f..%.3f s\n",
      cycle.in_warp().begin_s, cycle.in_warp().end_s, cycle.cutter().begin_s, cycle.cutter().end_s,
      cycle.yarn_sample().begin_s, cycle.yarn_sample().end_s);
  if (row_time.row1_s && row_time.row2_s) {
    const double extra = row_time.mean_s() - row_time.cycles_s;
    std::printf(
        "  knotting about %.1f s per row, from the heads' own sequence against an ideal plant: row 1 "
        "%.2f s, row 2 %.2f s (each from the left selvedge, then across to the sweep's start)\n    the %d "
        "knot cycles take %.1f s; the other %.1f s are the carriage's steps and the selectors' turns that "
        "outlast the grippers' return (%.3f s a knot), the settles and the way to the right selvedge\n",
        row_time.mean_s(), *row_time.row1_s, *row_time.row2_s, row_time.cycles, row_time.cycles_s, extra,
        extra / row_time.cycles);
  } else {
    std::printf("  knotting at least %.1f s per row (%d knot cycles back to back; %s)\n", row_time.cycles_s,
                row_time.cycles,
                c.recipe.design ? "the heads' sequence did not finish a row against an ideal plant"
                                : "no design: the carriage's steps and the selectors' turns are not counted");
  }
  std::string slots;
  for (std::size_t i = 0; i < k.slot_colours.size(); ++i)
    slots += (i ? ", " : "") + std::to_string(i) + "=" + k.slot_colours[i];
  std::printf("  magazine (every head alike): %zu slots [%s], %d knots of yarn per full slot\n",
              k.slot_colours.size(), slots.c_str(), k.knots_per_slot);
  if (!c.recipe.design) return;
  const design::Design& d = *c.recipe.design;
  std::vector<std::string> codes;
  for (const auto& colour : d.palette()) codes.push_back(colour.code);
  std::array<int, sequencer::kMaxKnottingHeads> at{};
  at.fill(-1);
  long moves = 0;
  int worst = 0;
  for (int r = 0; r < d.height(); ++r) {  // checked when the config was read: every colour has a slot
    const sequencer::RowKnotPlan p = sequencer::plan_row(k, c.machine_spec.width_m, d.row(r), codes, at);
    int row_moves = 0;
    for (int h = 0; h < k.heads; ++h)
      row_moves = std::max(row_moves, p.selector_moves[static_cast<std::size_t>(h)]);
    moves += row_moves;
    worst = std::max(worst, row_moves);
  }
  std::printf(
      "  design '%s': %d rows of %d knots; selector moves per row (the busiest head): mean %.1f, most %d\n",
      d.name().c_str(), d.height(), d.width(), d.height() > 0 ? static_cast<double>(moves) / d.height() : 0.0,
      worst);
}

void print_plan(const LoomConfig& c) {
  const motion::ProfileSet p(c.profile);
  const auto& w = p.beatup().warp();
  const auto& rc = c.recipe;
  std::printf("loom '%s' (%s): width %.3f m, control period %.3g ms\n", c.loom_id.c_str(), c.source.c_str(),
              c.machine_spec.width_m, c.run.period_s * 1e3);

  std::printf("\nbeat-up\n");
  std::printf("  linkage: crank %.4g, coupler %.4g, rocker %.4g, ground %.4g m; beater arm %.4g m, %.3g kg\n",
              c.profile.beatup.bar.crank, c.profile.beatup.bar.coupler, c.profile.beatup.bar.rocker,
              c.profile.beatup.bar.ground, c.profile.beatup.beater_arm_m, c.machine_spec.beater_mass_kg);
  std::printf(
      "  swing %.2f deg, stroke %.1f mm; warp window %.1f..%.1f deg from park (fell at %.1f deg), clear %.1f "
      "deg\n",
      motion::deg(p.beatup().dead_centres().swing), p.beatup().stroke_arc_m() * 1e3, motion::deg(w.enter),
      motion::deg(w.exit), motion::deg(w.fell), motion::deg(w.clear()));
  if (c.beat_force_target_n > 0.0) {
    std::printf(
        "  crank speed %.3f rad/s (%.1f r/min): the linkage's inverse dynamics put a %.1f N peak on the "
        "fell\n"
        "    at that speed (recipe.beat_force_target_n; every beat must land in %.0f..%.0f N)%s\n",
        c.profile.crank.velocity, c.profile.crank.velocity * 60.0 / motion::kTwoPi, c.beat_force_target_n,
        rc.beat_force_min_n, rc.beat_force_max_n,
        rc.crank_law.kind == motion::CrankLawKind::kConstant
            ? ""
            : "; master speed, the elliptic law speeds the crank up at the fell");
  } else {
    std::printf("  crank speed %.3f rad/s (%.1f r/min): fixed by recipe.crank_speed_rad_s\n",
                c.profile.crank.velocity, c.profile.crank.velocity * 60.0 / motion::kTwoPi);
  }
  {
    // The beat regulator (sequencer/beat_regulator.hpp): its bounds on this recipe, and when it acts.
    sequencer::SweepClock clock;
    const sequencer::BeatRegulatorLimits l = clock.configure(
        p, c.run.period_s, c.sequencer.beat_regulator, 0.5 * (rc.beat_force_min_n + rc.beat_force_max_n));
    const double v = c.profile.crank.velocity;
    if (!c.sequencer.beat_regulator.enabled) {
      std::printf("  beat force: open loop (the beat regulator is off)\n");
    } else {
      std::printf(
          "  beat force: closed loop when the beats are measured (a load cell: io.load_cell_channel = %d%s; "
          "in\n"
          "    simulation a scene naming beat_contact), else open loop: each beat's peak sets the next "
          "beat's crank\n"
          "    speed within %.2f..%.2f rad/s (x%.2f..x%.2f, up to %.1f %% per beat), aiming at %.0f N\n",
          c.io.wiring.load_cell_channel, c.io.wiring.load_cell_channel == 0 ? ", none" : "", v * l.min_scale,
          v * l.max_scale, l.min_scale, l.max_scale, 100.0 * l.max_step, l.target_n);
    }
  }
  std::printf(
      "  crank law %s; tables: %zu knots, %s, %s; measured error rocker %.2g rad, crank law %.2g rad (limit "
      "%.2g)\n",
      motion::crank_law_name(rc.crank_law.kind), c.profile.table_size,
      motion::interp_name(c.profile.table_interp), motion::precision_name(c.profile.table_precision),
      p.rocker_table_error(), p.crank_table_error(), c.profile.max_table_error_rad);

  std::printf("\nbeat sweep\n");
  std::printf("  %d beats per row (%d per position), pitch %.1f mm, beater %.0f mm with %.0f mm overlap\n",
              p.beats_per_row(), c.profile.beats_per_position, p.pitch_m() * 1e3,
              c.profile.beater_width_m * 1e3, c.profile.overlap_m * 1e3);
  const auto& pk = p.carriage_peaks();
  std::printf(
      "  %d carriage steps over %.3f m, each in %.1f ms of the clear window: peak %.3f m/s, %.2f m/s^2, %.0f "
      "m/s^3\n"
      "    (limits %.3g m/s, %.3g m/s^2, %.3g m/s^3; fastest crank that fits: %.2f rad/s)\n",
      p.cam().steps(), p.carriage_travel_m(), pk.step_time_s * 1e3, pk.speed_m_s, pk.accel_m_s2, pk.jerk_m_s3,
      c.profile.carriage_max_speed_m_s, c.profile.carriage_max_accel_m_s2, c.profile.carriage_max_jerk_m_s3,
      pk.max_crank_speed_rad_s);

  std::printf("\npick\n");
  std::printf(
      "  %.2f helix turns (width %.3f m / lead %.3f m) in %.3f s; acceleration limit %.0f rad/s^2 (carrier "
      "%.3g N on a %.3g kg shuttle: %.1f m/s^2)\n",
      c.profile.width_m / c.profile.helix_lead_m, c.profile.width_m, c.profile.helix_lead_m,
      p.pick().duration(), p.helix_accel_limit(), c.profile.carrier_force_n, c.profile.shuttle_mass_kg,
      p.shuttle_accel_limit_m_s2());

  std::printf("\nrow\n");
  const double shed_nominal = c.profile.shed.piston_travel_s + c.profile.shed.settle_s;
  const double row =
      c.sequencer.picks_per_row * (shed_nominal + p.pick().duration()) + p.crank_sweep().duration();
  std::printf(
      "  %u pick(s) per row: shed %.2f s (sensors must confirm within %.2f s) + pick %.2f s each; beat sweep "
      "%.2f s\n",
      c.sequencer.picks_per_row, shed_nominal, c.profile.shed.timeout_s, p.pick().duration(),
      p.crank_sweep().duration());
  // The knot cycle from the linkage and the servo's limits (checked when the config was read).
  std::optional<motion::KnotCycle> knot_cycle;
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) knot_cycle = motion::KnotCycle::build(c.knot_cycle);
  const KnotRowTime row_time =
      knot_cycle ? knot_row_time(c, *knot_cycle, p.carriage_travel_m()) : KnotRowTime{};
  if (knot_cycle) {
    // A knotted row compares whole with the weaver's whole row (~5 min knotting + 2 shed and pick + 3 beat).
    const double knot = row_time.mean_s();
    std::printf(
        "  about %.2f s per whole row: knotting %.2f s by %d heads + shed, pick and beat %.2f s (%.0fx "
        "faster than "
        "~600 s for the weaver's whole row)\n",
        knot + row, knot, c.knotting.heads, row, 600.0 / (knot + row));
  } else {
    std::printf("  about %.2f s per row (%.0fx faster than ~300 s by hand)\n", row, 300.0 / row);
  }

  print_safety_sensors(c);

  print_axes(c, p);
  print_knotting(c, knot_cycle, row_time);

  std::printf("\nCAN (for --hal socketcan)\n");
  std::string io_nodes = "I/O module node " + std::to_string(c.io.node);
  if (!c.io.modules.empty()) {
    io_nodes = "I/O modules: io node " + std::to_string(c.io.node) + " on bus 0";
    for (const IoModuleSpec& m : c.io.modules) {
      io_nodes += ", " + m.name + " node " + std::to_string(m.node) + " on bus " + std::to_string(m.bus);
    }
  }
  std::printf("  %s (%s); controller heartbeat %s\n", io_nodes.c_str(),
              c.io.kind == IoKind::kCan ? "on the bus" : "SIMULATED: needs --io simulated on hardware",
              c.can.master_node != 0 ? ("node " + std::to_string(c.can.master_node) + ", every " +
                                        std::to_string(c.can.master_heartbeat_ms) + " ms, consumers " +
                                        std::to_string(c.can.master_consumer_ms) + " ms")
                                           .c_str()
                                     : "off");
  std::printf("  heartbeats %u ms, lost after %u ms; bit rate %u bit/s\n", c.can.heartbeat_ms,
              c.can.heartbeat_timeout_ms, c.can.bitrate);
  // Per bus: the figure that bus' CAN master checks when it configures (bus i = the i-th --iface name).
  const std::size_t buses = drivers::bus_count(can_axis_config(c));
  for (std::size_t b = 0; b < buses; ++b) {
    std::string on_bus;
    for (const AxisSpec& a : c.axes) {
      if (a.bus == b) on_bus += (on_bus.empty() ? "" : ", ") + a.name + " " + std::to_string(a.node);
    }
    if (c.io.kind == IoKind::kCan) {
      const std::vector<std::size_t> io_buses = can_io_buses(c);
      for (std::size_t k = 0; k < io_buses.size(); ++k) {
        if (io_buses[k] != b) continue;
        on_bus += (on_bus.empty() ? "" : ", ") +
                  std::string(k == 0 ? "I/O " : "I/O " + c.io.modules[k - 1].name + " ") +
                  std::to_string(k == 0 ? c.io.node : c.io.modules[k - 1].node);
      }
    }
    const drivers::BusLoad load = can_bus_load(c, b);
    std::printf("  bus %zu (nodes %s) load: %s (budget %.0f %%)\n    %s\n", b, on_bus.c_str(),
                drivers::describe_bus_load(load).c_str(), c.can.bus_load_budget * 100.0,
                drivers::describe_bus_load_terms(load).c_str());
  }
  std::string nodes;
  for (const AxisSpec& a : c.axes) {
    nodes += (nodes.empty() ? "" : ", ") + std::to_string(a.node) +
             (buses > 1 ? "@bus" + std::to_string(a.bus) : "");
  }
  std::printf("  objects every drive (nodes %s) must support:\n", nodes.c_str());
  for (const auto& o : drivers::drive_objects()) std::printf("    %s\n", drivers::describe(o).c_str());
  std::string homing;
  for (const AxisSpec& a : c.axes) {
    if (a.homing)
      homing += (homing.empty() ? "" : ", ") + std::to_string(a.node) +
                (buses > 1 ? "@bus" + std::to_string(a.bus) : "");
  }
  if (!homing.empty()) {
    std::printf("  objects the homing drives (nodes %s) must support as well:\n", homing.c_str());
    for (const auto& o : drivers::homing_drive_objects())
      std::printf("    %s\n", drivers::describe(o).c_str());
  }
  for (const drivers::CanIoConfig& m : can_io_configs(c)) {
    if (c.io.modules.empty()) {
      std::printf("  objects the I/O module (node %u) must support:\n", m.node_id);
    } else {
      std::printf("  objects the I/O module %s (node %u; %s) must support:\n",
                  module_key(c, m.module).c_str(), m.node_id,
                  m.module == 0 ? "every signal no other module lists"
                                : ("signals " + io_module_signals(c.io.modules[m.module - 1u])).c_str());
    }
    for (const auto& o :
         drivers::io_module_objects(drivers::module_wiring(m.wiring, m.module), m.input_group_bits)) {
      std::printf("    %s\n", drivers::describe(o).c_str());
    }
  }
}

// Per node with an EDS (axes.<name>.eds, io.eds, io_modules.<name>.eds): what its description offers,
// what the loom will use, and one line with the EDS's file:line and a remedy for everything it lacks.
// Returns the number of nodes the loom cannot run with as described.
int print_eds(const LoomConfig& c) {
  const std::vector<EdsNode> nodes = eds_nodes(c);
  if (nodes.empty()) return 0;
  namespace eds = drivers::eds;
  std::printf("\nnodes against their EDS (CiA 306)\n");
  int refused = 0;
  for (const EdsNode& n : nodes) {
    const eds::NodeProfile& p = n.check.profile;
    const auto hex = [](const std::optional<std::uint32_t>& v) {
      char b[16] = "?";
      if (v) std::snprintf(b, sizeof b, "0x%08X", *v);
      return std::string(b);
    };
    std::printf("  %s (%s): vendor %s product %s revision %s; %d RPDOs, %d TPDOs, mapping %s%s%s\n",
                n.needs.node.c_str(), n.eds.file.c_str(), hex(p.vendor).c_str(), hex(p.product).c_str(),
                hex(p.revision).c_str(), p.rpdos, p.tpdos, p.fixed_mapping ? "fixed" : "dynamic",
                p.supported_modes ? (", modes " + eds::describe_modes(*p.supported_modes)).c_str() : "",
                p.consumer_heartbeat ? ", watches the controller (0x1016)"
                                     : ", cannot watch the controller (no 0x1016)");
    for (const eds::Finding& f : n.check.findings)
      std::printf("    %s\n", eds::format(n.eds, n.needs, f).c_str());
    if (n.check.ok()) {
      std::printf(
          "    the loom configures %zu values at bring-up (only those that differ are written; loomctl dcf "
          "writes them as a DCF)\n",
          n.writes.size());
    } else {
      ++refused;
    }
  }
  return refused;
}

void print_scene(const Scene& s) {
  std::printf("\nscene '%s' (%s), seed %llu\n", s.spec.name.c_str(), s.source.c_str(),
              static_cast<unsigned long long>(s.spec.seed));
  std::string effects;
  for (const auto& e : s.spec.effects) effects += (effects.empty() ? "" : ", ") + e;
  std::printf("  effects: %s\n", effects.c_str());
  std::printf("  faults injected: %zu\n", s.spec.faults.size());
}

}  // namespace

int run_check(const CheckArgs& a) {
  if (a.keys) {
    print_keys();
    return 0;
  }
  try {
    Scene scene;
    std::string config_path = a.config;
    if (!a.scene.empty()) {
      scene = load_scene(a.scene);
      if (config_path.empty() && !scene.config_path.empty()) {
        config_path = (std::filesystem::path(a.scene).parent_path() / scene.config_path).string();
      }
    }
    const LoomConfig c = config_path.empty() ? default_loom_config() : load_loom_config(config_path);
    if (!a.scene.empty()) (void)check_scene_fits(scene, c);
    print_plan(c);
    const int refused = print_eds(c);
    if (!a.scene.empty()) print_scene(scene);
    if (refused > 0) {
      std::fprintf(stderr,
                   "loomctl: check: %d node(s) lack what the loom needs (the error lines above, each with "
                   "its EDS file:line) — nothing was moved\n",
                   refused);
      return 2;
    }
    std::printf("\ncheck: OK — nothing was moved\n");
    return 0;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "loomctl: %s\n", e.what());
    return 2;
  }
}

}  // namespace loom::firmware
