// Cross-field checks of a loom file, each at the line that is wrong, and each module's own validation
// at parse time (the CAN master's timing and bus load, the motion's buildability and capacities, the
// beat's resolution by the loop period): a config that parses but cannot be woven is refused here,
// never at the first row.
#include "checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <utility>

#include "derive.hpp"
#include "drives.hpp"
#include "loom/drivers/bus_load.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"

namespace loom::firmware::detail {
namespace {

// Longest plausible row: a recipe whose row takes longer than this is a typo, not a carpet.
constexpr double kMaxRowSeconds = 3600.0;

// With knotting heads, every row of the recipe's design must be tied by them: its width is the loom's
// knots per row and every colour sits in a magazine slot (refused naming the colour and the first knot).
void check_design_fits_heads(const TomlReader& r, const LoomConfig& c) {
  if (c.knotting.mode != sequencer::KnottingMode::kHeads || !c.recipe.design) return;
  try {
    (void)knot_program(c, 0, 0);
  } catch (const std::invalid_argument& e) {
    r.fail("recipe.design", '"' + c.recipe.design_file + '"', e.what());
  }
}

// The key (and its value) a refusal of the CAN master's configuration is pinned to: the key that sets the
// field. Fields no single key sets, or whose own key's range already refuses every bad value, keep the
// keys their refusals have always named (the tests pin the messages): can.heartbeat_timeout_ms, or
// can.bus_load_budget for the bus, bit-rate and axis-count limits.
std::pair<std::string, std::string> can_master_key(const LoomConfig& c,
                                                   const drivers::CanAxisConfigFault& f) {
  using F = drivers::CanAxisField;
  const AxisSpec* axis = f.axis < c.axes.size() ? &c.axes[f.axis] : nullptr;
  const std::string on_axis = axis != nullptr ? "axes." + axis->name + "." : "";
  switch (f.field) {
    case F::kHeartbeatProducer:
      return {"can.heartbeat_ms", std::to_string(c.can.heartbeat_ms)};
    case F::kMasterHeartbeat:
      return {"can.master_heartbeat_ms", std::to_string(c.can.master_heartbeat_ms)};
    case F::kSdoTimeout:
      return {"can.sdo_timeout_ms", std::to_string(c.can.sdo_timeout_ms)};
    case F::kCountsPerUnit:
      if (axis != nullptr) return {on_axis + "counts_per_rev", fmt_num(axis->counts_per_rev)};
      break;
    case F::kFerrorMin:
    case F::kFerrorK:
      if (axis != nullptr) return {on_axis + "ferror_min", fmt_num(axis->ferror_min)};
      break;
    case F::kHomingMethod:
    case F::kHomingSpeed:
    case F::kHomeOffset:
      if (axis != nullptr) return {on_axis + "homing_method", std::to_string(axis->homing_method)};
      break;
    case F::kNodeId:
    case F::kNodeIdTaken:
      if (axis != nullptr) return {on_axis + "node", std::to_string(axis->node)};
      break;
    case F::kNodeIdIsMaster:  // the drive's node id or the master's, whichever the file says
      if (axis != nullptr) {
        return {on_axis + "node|can.master_node",
                std::to_string(axis->node) + "|" + std::to_string(c.can.master_node)};
      }
      return {"can.master_node", std::to_string(c.can.master_node)};
    case F::kBus:
      if (axis != nullptr) return {on_axis + "bus", std::to_string(axis->bus)};
      break;
    case F::kMasterNode:
      return {"can.master_node", std::to_string(c.can.master_node)};
    case F::kAxisCount:
    case F::kBitrate:
    case F::kBusLoadBudget:
      return {"can.bus_load_budget", fmt_num(c.can.bus_load_budget)};
    case F::kRatedEffort:
    case F::kBringUpTimeouts:
    case F::kCyclePeriod:
    case F::kHeartbeatConsumer:
    case F::kBootTimeout:
    case F::kStateTimeout:
    case F::kTpdo2EveryN:
    case F::kOperationalTimeout:
    case F::kOtherFrames:
      break;
  }
  return {"can.heartbeat_timeout_ms", std::to_string(c.can.heartbeat_timeout_ms)};
}

// The key (and its value) a refusal of the I/O module's configuration is pinned to: a signal's bit is set
// by io.<signal>_bit (a knotting head's by io.<signal>_bits), as the key table has it; the rest by io.node.
std::pair<std::string, std::string> io_module_key(const LoomConfig& c, const drivers::IoConfigFault& f) {
  if (f.field == drivers::IoField::kSignalBit) {
    const std::string path = "io." + f.signal + (f.head == 0 ? "_bit" : "_bits");
    for (const Key& k : keys()) {
      if (k.path == path) return {k.path, k.value(c)};
    }
  }
  return {"io.node", std::to_string(c.io.node)};
}

// The key a refusal of the knotting spec is pinned to: the one that sets the refused field.
const char* knotting_key(sequencer::KnottingField f) {
  using F = sequencer::KnottingField;
  switch (f) {
    case F::kKnotsPerDm:
      return "knotting.knots_per_dm";
    case F::kRowsPerDm:
      return "knotting.rows_per_dm";
    case F::kHeads:
      return "knotting.heads";
    case F::kHeadSpacing:
      return "knotting.head_spacing_m";
    case F::kSlotColours:
      return "knotting.slot_colours";
    case F::kKnotsPerSlot:
      return "knotting.knots_per_slot";
    case F::kPlacementTolerance:
      return "knotting.placement_tolerance_m";
  }
  return "knotting.mode";
}

// The key (and its value as the file writes it) a refusal of the sequencer's configuration is pinned
// to: the key that sets the field. The machine's constants, which no key sets, are pinned to the key
// they relate to.
std::pair<std::string, std::string> sequencer_key(const LoomConfig& c, const sequencer::SequencerFault& f) {
  using F = sequencer::SequencerField;
  const auto ms = [](double s) { return fmt_num(s * 1e3); };
  const auto key = [&](const char* path) {
    return std::pair<std::string, std::string>{path, value_of(c, path)};
  };
  switch (f.field) {
    case F::kPeriod:
    case F::kArrivalGrace:  // a machine constant, counted in periods
      return {"timing.period_ms", ms(c.run.period_s)};
    case F::kBeatsPerPosition:
      return key("recipe.beats_per_position");
    case F::kPicksPerRow:
      return key("recipe.picks_per_row");
    case F::kAxes:
      return {"axes", ""};
    case F::kAxisMaxSpeed:
      if (f.axis < c.axes.size())
        return {"axes." + c.axes[f.axis].name + ".max_speed", fmt_num(c.axes[f.axis].max_speed)};
      return {"axes", ""};
    case F::kDebounceTicks:
      return key("timing.debounce_ticks");
    case F::kSensorDiscrepancy:
      return {"timing.sensor_discrepancy_ms", ms(c.run.sensor_discrepancy_s)};
    case F::kCrankParkPosition:
      return key("beatup.crank_park_position_rad");
    case F::kCarriageHome:
      return key("carriage.home_position_m");
    case F::kHelixLeftPosition:
      return key("helix.left_position_rad");
    case F::kEnableTimeout:
      return key("timing.enable_timeout_s");
    case F::kPickTimeoutMargin:
      return key("timing.pick_timeout_margin_s");
    case F::kStaleTimeout:
      return {"timing.stale_timeout_ms", ms(c.run.stale_timeout_s)};
    case F::kDiagnosisWindow:
      return key("can.heartbeat_timeout_ms");  // the window follows from it on CAN
    case F::kRowSaveTimeout:
      return key("timing.row_save_timeout_s");
    case F::kSelvedgeSensorWindow:
    case F::kShuttleFollowTolerance:
      return key("loom.width_m");  // constants of the shuttle's path
    case F::kKnottingHeads:
      return key("knotting.heads");
    case F::kKnottingMode:
      return key("knotting.mode");
    case F::kSlotColours:
      return key("knotting.slot_colours");
    case F::kSelectorLimits:
      return key("knotting.selector_accel_rad_s2");
    case F::kKnotterSettings:
      return key("knotting.take_position_rad");
    case F::kBeatRegulator:  // the regulator's constants: about the band it holds
      return key("recipe.beat_force_min_n");
  }
  return {"timing.period_ms", ms(c.run.period_s)};
}

// The loop period must resolve the beat. A beat presses the comb into the fell for only a short arc of
// crank (the simulated load cell: the last 5 mm of the tip's travel, about 33 deg of crank); its force
// rises through the contact and peaks as the beater leaves the cloth. The load cell is read once per
// tick, so the peak the sequencer records (and checks against the band) can come up to one tick of crank
// travel early. Measured with the default scene and recipe (90 N target, 80..100 N band, 16.06 rad/s):
//   period ms    2     4     5     8     10    12    15    16    18    19    20
//   deg/tick     1.8   3.7   4.6   7.4   9.2   11.0  13.8  14.7  16.6  17.5  18.4
//   min peak N   89.3  88.7  88.3  86.9  85.6  84.2  82.6  81.6  79.8  78.4  78.8
// about 0.45..0.6 N lost per degree of crank per tick, so 20 ms beats fall out of the band. The sampling
// may use at most half of the band's 10 N headroom below the target (the other half is for servo lag,
// load-cell noise and speed ripple): at most 10 deg of crank per tick at the beat, which loses ~4.6 N.
constexpr double kMaxBeatCrankDegPerTick = 10.0;

}  // namespace

void check_relations(const TomlReader& r, const LoomConfig& c) {
  const auto present = [&](const std::string& path) { return r.root().at_path(path).node() != nullptr; };
  // A drive's node id is used once on the bus (the I/O module's is checked with it in check_can).
  for (std::size_t i = 1; i < c.axes.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (c.axes[i].node != c.axes[j].node || c.axes[i].bus != c.axes[j].bus) continue;
      const std::string ki = "axes." + c.axes[i].name + ".node", kj = "axes." + c.axes[j].name + ".node";
      const bool i_here = present(ki), j_here = present(kj);
      const toml::node* ni = r.root().at_path(ki).node();
      const toml::node* nj = r.root().at_path(kj).node();
      // At the later of the two lines the file writes (the one the file repeats).
      const bool at_i = i_here && (!j_here || ni->source().begin.line >= nj->source().begin.line);
      r.fail(at_i ? ki : kj, std::to_string(c.axes[i].node), "node id already used by " + (at_i ? kj : ki));
    }
  }
  const auto& m = c.machine_spec;
  // The beat-up must be a Grashof crank-rocker: the crank turns fully, the rocker swings the beater.
  if (motion::classify(m.beatup.bar) != motion::GrashofClass::kCrankRocker) {
    const auto& b = m.beatup.bar;
    std::ostringstream os;
    os << "the linkage (crank " << b.crank << ", coupler " << b.coupler << ", rocker " << b.rocker
       << ", ground " << b.ground << " m) is a " << motion::grashof_class_name(motion::classify(b))
       << ", not a crank-rocker: the crank must be the shortest link and shortest + longest <= the other two";
    r.fail("beatup.crank_m", fmt_num(b.crank), os.str());
  }
  if (m.beater_width_m >= m.width_m) {
    r.fail("beatup.beater_width_m", fmt_num(m.beater_width_m),
           "must be narrower than loom.width_m = " + fmt_num(m.width_m));
  }
  if (c.recipe.overlap_m >= m.beater_width_m) {
    r.fail("recipe.overlap_m", fmt_num(c.recipe.overlap_m),
           "must be less than beatup.beater_width_m = " + fmt_num(m.beater_width_m) +
               " (the carriage must step forward)");
  }
  if (c.recipe.beat_force_min_n >= c.recipe.beat_force_max_n) {
    r.fail("recipe.beat_force_max_n", fmt_num(c.recipe.beat_force_max_n),
           "must exceed recipe.beat_force_min_n = " + fmt_num(c.recipe.beat_force_min_n));
  }
  if (c.recipe.beat_force_target_n > 0.0 && (c.recipe.beat_force_target_n < c.recipe.beat_force_min_n ||
                                             c.recipe.beat_force_target_n > c.recipe.beat_force_max_n)) {
    r.fail("recipe.beat_force_target_n", fmt_num(c.recipe.beat_force_target_n),
           "must lie in the band [beat_force_min_n, beat_force_max_n] = [" +
               fmt_num(c.recipe.beat_force_min_n) + ", " + fmt_num(c.recipe.beat_force_max_n) + "]");
  }
  if (c.run.stale_timeout_s < 2.0 * c.run.period_s) {
    r.fail("timing.stale_timeout_ms", fmt_num(c.run.stale_timeout_s * 1e3),
           "must be at least two periods (timing.period_ms = " + fmt_num(c.run.period_s * 1e3) + ")");
  }
  // At the key that sets the refused field, or at knotting.mode when the file takes that key from the
  // embedded default (the mode is what makes the default matter).
  if (const std::optional<sequencer::KnottingFault> f = sequencer::find_fault(c.knotting, m.width_m)) {
    const std::string named = knotting_key(f->field);
    const std::string key = present(named) ? named : "knotting.mode";
    r.fail(key, value_of(c, key), f->message);
  }
  check_design_fits_heads(r, c);
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    // The knotting linkage must reach its three precision points on one branch, in order, with a usable
    // transmission angle and no dead centre in the stroke, and the servo must move it (the knot cycle's
    // checks).
    try {
      (void)motion::KnotCycle::build(c.knot_cycle);
    } catch (const motion::KnotCycleError& e) {
      // About the servo's torque: the knotting servo's drive is the fact to change.
      if (e.field() == motion::KnotCycleField::kMaxTorque) {
        const auto knotter = std::find_if(c.axes.begin(), c.axes.end(), [](const AxisSpec& a) {
          return a.role == hal::AxisRole::kKnotter;
        });
        if (knotter != c.axes.end() && !knotter->drive.empty()) {
          r.fail("axes." + knotter->name + ".drive", "\"" + knotter->drive + "\"",
                 std::string("the knotting servo's drive: ") + e.what());
        }
      }
      r.fail("knotting.linkage.crank_m", fmt_num(c.knot_cycle.crank.length_m),
             std::string("the knotting linkage: ") + e.what());
    } catch (const motion::MotionError& e) {
      r.fail("knotting.linkage.crank_m", fmt_num(c.knot_cycle.crank.length_m),
             std::string("the knotting linkage: ") + e.what());
    }
  }
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    // One knotting servo and one colour selector per head, in the axes table.
    for (const hal::AxisRole role : {hal::AxisRole::kKnotter, hal::AxisRole::kSelector}) {
      const auto n =
          std::count_if(c.axes.begin(), c.axes.end(), [&](const AxisSpec& a) { return a.role == role; });
      if (n != c.knotting.heads) {
        r.fail("knotting.heads", std::to_string(c.knotting.heads),
               "the loom has " + std::to_string(n) + " axes with role = \"" + hal::axis_role_name(role) +
                   "\": every head needs its knotting servo and its colour selector ([axes.<name>] role = "
                   "\"knotter\" "
                   "and role = \"selector\", one of each per head)");
      }
    }
  }
  if (m.shed.release_timeout_s >= m.shed.timeout_s) {
    r.fail("shedding.release_timeout_s", fmt_num(m.shed.release_timeout_s),
           "must be shorter than shedding.timeout_s = " + fmt_num(m.shed.timeout_s));
  }
}

void check_can(const LoomConfig& c, const Fail& fail) {
  const drivers::CanAxisPortConfig cc = can_axis_config(c);
  if (const std::optional<drivers::CanAxisConfigFault> f = drivers::find_fault(cc)) {
    const auto [key, value] = can_master_key(c, *f);
    fail(key, value, "the CAN master refuses it: " + f->message);
  }
  if (c.io.kind == IoKind::kCan) {
    // Node ids are unique per bus: each module against the axes and the modules before it on its bus.
    const std::vector<std::size_t> buses = can_io_buses(c);
    const auto node_key = [&](std::size_t k) {
      return k == 0 ? std::string("io.node") : "io_modules." + c.io.modules[k - 1].name + ".node";
    };
    const auto node_of = [&](std::size_t k) { return k == 0 ? c.io.node : c.io.modules[k - 1].node; };
    for (std::size_t k = 0; k < buses.size(); ++k) {
      for (const AxisSpec& a : c.axes) {
        if (a.bus == buses[k] && a.node == node_of(k)) {
          fail(node_key(k), std::to_string(node_of(k)), "node id already used by axes." + a.name + ".node");
        }
      }
      for (std::size_t j = 0; j < k; ++j) {
        if (buses[j] == buses[k] && node_of(j) == node_of(k)) {
          fail(node_key(k), std::to_string(node_of(k)),
               "node id already used by " + node_key(j) + " on bus " + std::to_string(buses[k]));
        }
      }
    }
    if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
      // One bit per head: a list of another length is a wiring that does not match the heads fitted.
      for (const auto& [name, signals] : {std::pair{"io.gripper_close_bits", &c.io.gripper_close},
                                          std::pair{"io.cutter_bits", &c.io.cutter},
                                          std::pair{"io.yarn_present_bits", &c.io.yarn_present}}) {
        if (signals->bits.size() != static_cast<std::size_t>(c.knotting.heads)) {
          std::string list;
          for (int b : signals->bits) list += (list.empty() ? "" : ", ") + std::to_string(b);
          fail(name, "[" + list + "]",
               std::to_string(signals->bits.size()) + " bits for knotting.heads = " +
                   std::to_string(c.knotting.heads) + ": one per head, head 1 first");
        }
      }
    }
    if (const std::optional<drivers::IoConfigFault> f = drivers::find_fault(can_io_configs(c).front())) {
      const auto [key, value] = io_module_key(c, *f);
      std::string msg = f->message;
      if (f->shared_module != 0) {  // the driver numbers modules; the file names them
        const std::size_t k = f->shared_module;
        msg += " (both on " +
               (k <= c.io.modules.size() ? "io_modules." + c.io.modules[k - 1].name
                                         : "I/O module " + std::to_string(k)) +
               ")";
      }
      fail(key, value, "the I/O module refuses it: " + msg);
    }
  }
  // Each bus has its own master, SYNC and budget: a bus is judged by its own nodes' frames.
  const std::size_t buses = drivers::bus_count(cc);
  for (std::size_t b = 0; b < buses; ++b) {
    if (const drivers::Status s = drivers::check_bus_load(can_bus_load(c, b), c.can.bus_load_budget); !s) {
      fail("can.bus_load_budget", fmt_num(c.can.bus_load_budget),
           buses == 1 ? s.message() : "bus " + std::to_string(b) + ": " + s.message());
    }
  }
}

void check_motion(const LoomConfig& c, const Fail& fail) {
  const bool from_force = c.recipe.beat_force_target_n > 0.0;
  const std::string speed_key = from_force ? "recipe.beat_force_target_n" : "recipe.crank_speed_rad_s";
  const std::string speed_value =
      fmt_num(from_force ? c.recipe.beat_force_target_n : c.recipe.crank_speed_rad_s);
  std::optional<motion::ProfileSet> set;
  try {
    set.emplace(c.profile);
  } catch (const motion::MotionError& e) {
    std::string why = std::string("motion profiles cannot be built: ") + e.what();
    if (from_force)
      why += " (the force target asks for a crank speed of " + fmt_num(c.profile.crank.velocity) + " rad/s)";
    fail(speed_key, speed_value, why);
  }
  if (set->beats_per_row() > sequencer::kMaxBeatsPerRow) {
    fail("recipe.beats_per_position", std::to_string(c.recipe.beats_per_position),
         "gives " + std::to_string(set->beats_per_row()) + " beats per row on a " +
             fmt_num(c.machine_spec.width_m) + " m loom; the sequencer holds at most " +
             std::to_string(sequencer::kMaxBeatsPerRow));
  }
  // The sequencer's own validation (its capacities, calibration offsets, time-outs in ticks), at the key
  // that sets the refused field.
  if (const std::optional<sequencer::SequencerFault> f = sequencer::find_fault(c.sequencer, *set)) {
    const auto [key, value] = sequencer_key(c, *f);
    fail(key, value, f->message);
  }
  check_core_drives(c, *set, fail);
  // A homed crank comes to rest at its home point before anything else moves: the beater must be clear
  // of the warp there, or the carriage could never home or move after it.
  const AxisSpec& crank = c.axes[hal::index(hal::CoreAxis::kBeatCrank)];
  if (crank.homing) {
    const motion::WarpWindow& w = set->beatup().warp();
    const double phase =
        motion::wrap_two_pi(crank.home_offset - c.machine_spec.calibration.crank_park_position_rad);
    if (phase > w.enter && phase < w.exit) {
      fail("axes." + crank.name + ".home_offset", fmt_num(crank.home_offset),
           "the beater is inside the warp at the crank's home point (" + fmt_num(motion::deg(phase)) +
               " deg from park; the warp spans " + fmt_num(motion::deg(w.enter)) + ".." +
               fmt_num(motion::deg(w.exit)) + " deg): put the home switch where the beater is clear");
    }
  }
  const double pick_s = set->pick().duration(), sweep_s = set->crank_sweep().duration();
  if (!std::isfinite(pick_s) || pick_s <= 0.0 || pick_s > 600.0) {
    fail("helix.max_accel_rad_s2", fmt_num(c.machine_spec.helix.acceleration),
         "a pick would take " + fmt_num(pick_s) + " s (must end within 600 s)");
  }
  const double row_s = c.recipe.picks_per_row * (c.machine_spec.shed.timeout_s + pick_s) + sweep_s;
  if (!std::isfinite(sweep_s) || !std::isfinite(row_s) || row_s > kMaxRowSeconds) {
    fail(speed_key, speed_value,
         "a row would take up to " + fmt_num(row_s) + " s (beat sweep " + fmt_num(sweep_s) + " s); at most " +
             fmt_num(kMaxRowSeconds) + " s");
  }
}

void check_beat_resolution(const LoomConfig& c, const Fail& fail) {
  // The crank speed at the fell (rad/s), at the fastest beat the loom may run: the beat regulator may
  // beat up to its speed bound above the recipe's (sequencer::BeatRegulatorConfig; open loop: 1).
  const sequencer::BeatRegulatorConfig& reg = c.sequencer.beat_regulator;
  const double fastest = reg.enabled ? std::max(1.0, reg.max_speed_scale) : 1.0;
  const double omega = c.profile.crank.velocity * beat_speed_ratio(c) * fastest;
  const double deg_per_tick = motion::deg(omega * c.run.period_s);
  if (!(deg_per_tick > kMaxBeatCrankDegPerTick)) return;
  // The largest period this recipe allows, rounded down to 0.01 ms so that it is itself accepted.
  const double max_period_ms = std::floor(motion::rad(kMaxBeatCrankDegPerTick) / omega * 1e5) / 100.0;
  char why[512];
  std::snprintf(
      why, sizeof why,
      "the crank turns %.1f deg per tick at the fastest beat (%.2f rad/s, the beat regulator's bound x%.2f "
      "on the recipe's speed); at most %.0f deg per tick, i.e. "
      "period_ms <= %.2f for this recipe: a beat's contact with the fell lasts only a few ticks and the "
      "load cell, read once per tick, can miss its peak by up to a tick of crank travel (simulated at "
      "20 ms with the default recipe: beats down to 78.8 N against the 80 N minimum)",
      deg_per_tick, omega, fastest, kMaxBeatCrankDegPerTick, max_period_ms);
  fail("timing.period_ms", fmt_num(c.run.period_s * 1e3), why);
}

}  // namespace loom::firmware::detail
