// Loom config and scene parsing. Values are read into the same structs the modules use, then the
// profile set is built once here as the final check: a config that parses but cannot be woven (the
// crank cannot reach speed before the first beat, the carriage step breaks its limits) is refused now,
// with the motion module's message, rather than at the first row.
#include <algorithm>
#include <fstream>
#include <sstream>

#include "loom/firmware/config.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/mass_properties.hpp"
#include "loom/motion/profile_crank.hpp"
#include "toml_reader.hpp"

namespace loom::firmware {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw ConfigError(path + ": cannot open file");
  std::ostringstream os;
  os << f.rdbuf();
  return os.str();
}

std::string in_range(double v, double lo, double hi) {
  if (v >= lo && v <= hi) return "";
  std::ostringstream os;
  os << "must be in [" << lo << ", " << hi << "]";
  return os.str();
}

}  // namespace

LoomConfig parse_loom_config(const std::string& text, const std::string& source) {
  TomlReader r(text, source);
  LoomConfig c;
  c.source = source;
  r.string("loom.id", c.loom_id);
  if (c.loom_id.empty() || c.loom_id.find_first_of(" ./*") != std::string::npos) {
    r.fail("loom.id", '"' + c.loom_id + '"', "must be non-empty without spaces, dots, slashes or '*'");
  }
  auto& p = c.profile;
  r.number("loom.width_m", p.width_m, [](double v) { return in_range(v, 0.2, 10.0); });

  auto& bar = p.beatup.bar;
  r.number("beatup.crank_m", bar.crank, positive);
  r.number("beatup.coupler_m", bar.coupler, positive);
  r.number("beatup.rocker_m", bar.rocker, positive);
  r.number("beatup.ground_m", bar.ground, positive);
  r.number("beatup.beater_arm_m", p.beatup.beater_arm_m, positive);
  std::string branch = "positive", fell = "extended";
  r.string("beatup.branch", branch, {"positive", "negative"});
  p.beatup.branch = branch == "positive" ? motion::Branch::kPositive : motion::Branch::kNegative;
  r.string("beatup.fell_at", fell, {"extended", "folded"});
  p.beatup.fell_at = fell == "extended" ? motion::FellSide::kExtended : motion::FellSide::kFolded;
  r.number("beatup.warp_depth_m", p.beatup.warp_depth_m, positive);
  r.number("beatup.crank_speed_rad_s", p.crank.velocity, [](double v) { return in_range(v, 0.1, 100.0); });
  // A loom builder asks for the beat force (default 90 N, thesis: 80–100 N) or fixes the crank speed;
  // from a force, the crank speed comes from the linkage's inverse dynamics (the beater force is
  // inertial, so it scales with ω²).
  const bool speed_given = r.root().at_path("beatup.crank_speed_rad_s").node() != nullptr;
  const bool force_given = r.root().at_path("beatup.beat_force_target_n").node() != nullptr;
  double force_target = 90.0;
  r.number("beatup.beat_force_target_n", force_target, [](double v) { return in_range(v, 1.0, 1000.0); });
  if (speed_given && force_given) {
    r.fail("beatup.beat_force_target_n", std::to_string(force_target),
           "give either beat_force_target_n or crank_speed_rad_s, not both");
  }
  c.beat_force_target_n = speed_given ? 0.0 : force_target;
  double beater_kg = 2.5;
  r.number("beatup.beater_mass_kg", beater_kg, positive);
  r.number("beatup.crank_accel_rad_s2", p.crank.acceleration, positive);
  r.number("beatup.crank_jerk_rad_s3", p.crank.jerk, positive);
  r.number("beatup.beater_width_m", p.beater_width_m, positive);
  r.number("beatup.overlap_m", p.overlap_m, non_negative);
  double margin_deg = motion::deg(p.cam_margin_rad);
  r.number("beatup.cam_margin_deg", margin_deg, [](double v) { return in_range(v, 0.0, 90.0); });
  p.cam_margin_rad = motion::rad(margin_deg);
  std::int64_t table = static_cast<std::int64_t>(p.table_size);
  r.integer("beatup.table_size", table, 64, 1 << 20);
  p.table_size = static_cast<std::size_t>(table);
  std::string interp = motion::interp_name(p.table_interp), precision = motion::precision_name(p.table_precision);
  r.string("beatup.interp", interp, {"linear", "cubic", "quintic"});
  motion::parse_interp(interp.c_str(), p.table_interp);
  r.string("beatup.table_precision", precision, {"double", "float32"});
  motion::parse_precision(precision.c_str(), p.table_precision);
  r.number("beatup.max_table_error_rad", p.max_table_error_rad, positive);
  std::string law = motion::crank_law_name(p.crank_law.kind);
  r.string("beatup.crank_law", law, {"constant", "elliptic"});
  motion::parse_crank_law(law.c_str(), p.crank_law.kind);
  r.number("beatup.ellipse_e", p.crank_law.ellipse_e, [](double v) { return v >= 0.0 && v < 1.0 ? "" : "must be in [0, 1)"; });
  std::int64_t lobes = p.crank_law.ellipse_lobes;
  r.integer("beatup.ellipse_lobes", lobes, 1, 16);
  p.crank_law.ellipse_lobes = static_cast<int>(lobes);
  double phi02_deg = motion::deg(p.crank_law.ellipse_phi02_rad);
  r.number("beatup.ellipse_phi02_deg", phi02_deg, [](double v) { return in_range(v, -360.0, 360.0); });
  p.crank_law.ellipse_phi02_rad = motion::rad(phi02_deg);
  r.number("beatup.crank_park_position_rad", c.sequencer.crank_park_position_rad);

  r.number("carriage.max_speed_m_s", p.carriage_max_speed_m_s, positive);
  r.number("carriage.max_accel_m_s2", p.carriage_max_accel_m_s2, positive);
  r.number("carriage.max_jerk_m_s3", p.carriage_max_jerk_m_s3, positive);
  r.number("carriage.jerk_m_s3", c.sequencer.carriage.jerk, positive);
  r.number("carriage.home_position_m", c.sequencer.carriage_home_m);
  c.sequencer.carriage.velocity = p.carriage_max_speed_m_s;
  c.sequencer.carriage.acceleration = p.carriage_max_accel_m_s2;

  r.number("helix.lead_m", p.helix_lead_m, positive);
  r.number("helix.left_position_rad", c.sequencer.helix_left_position_rad);
  r.number("helix.max_speed_rad_s", p.helix.velocity, positive);
  r.number("helix.max_accel_rad_s2", p.helix.acceleration, positive);
  r.number("helix.jerk_rad_s3", p.helix.jerk, positive);
  r.number("helix.carrier_force_n", p.carrier_force_n, positive);
  r.number("helix.shuttle_mass_kg", p.shuttle_mass_kg, positive);

  std::int64_t per_position = p.beats_per_position;
  r.integer("recipe.beats_per_position", per_position, 1, 16);
  p.beats_per_position = static_cast<int>(per_position);
  std::int64_t picks = c.sequencer.picks_per_row;
  r.integer("recipe.picks_per_row", picks, 1, 16);
  c.sequencer.picks_per_row = static_cast<std::uint32_t>(picks);
  std::int64_t debounce = c.sequencer.debounce_ticks;
  r.integer("timing.debounce_ticks", debounce, 1, 100);
  c.sequencer.debounce_ticks = static_cast<int>(debounce);

  r.number("shedding.piston_travel_s", p.shed.piston_travel_s, positive);
  c.machine.piston_travel_s = p.shed.piston_travel_s;
  r.number("shedding.timeout_s", p.shed.timeout_s, positive);
  r.number("shedding.earliest_fraction", p.shed.earliest_fraction, [](double v) { return in_range(v, 0.0, 0.99); });
  r.number("shedding.release_timeout_s", p.shed.release_timeout_s, positive);
  double settle_ms = p.shed.settle_s * 1e3;
  r.number("shedding.settle_ms", settle_ms, non_negative);
  p.shed.settle_s = settle_ms * 1e-3;

  double period_ms = 2.0, stale_ms = 50.0;
  r.number("timing.period_ms", period_ms, [](double v) { return in_range(v, 0.25, 20.0); });
  r.number("timing.enable_timeout_s", c.sequencer.enable_timeout_s, positive);
  r.number("timing.pick_timeout_margin_s", c.sequencer.pick_timeout_margin_s, positive);
  r.number("timing.stale_timeout_ms", stale_ms, positive);
  c.sequencer.period_s = period_ms * 1e-3;
  c.sequencer.stale_timeout_s = stale_ms * 1e-3;
  if (c.sequencer.stale_timeout_s < 2.0 * c.sequencer.period_s) {
    r.fail("timing.stale_timeout_ms", std::to_string(stale_ms), "must be at least two periods");
  }
  c.machine.period_s = c.sequencer.period_s;
  c.machine.width_m = p.width_m;
  c.machine.helix_lead_m = p.helix_lead_m;
  c.machine.beatup = p.beatup;
  c.machine.crank_park_position_rad = c.sequencer.crank_park_position_rad;

  std::int64_t v = 0;
  v = c.can.bitrate;
  r.integer("can.bitrate", v, 10'000, 1'000'000);
  c.can.bitrate = static_cast<std::uint32_t>(v);
  r.number("can.bus_load_budget", c.can.bus_load_budget, [](double x) { return in_range(x, 0.05, 1.0); });
  const auto node = [&](const char* key, std::uint8_t& out) {
    std::int64_t n = out;
    r.integer(key, n, 1, 127);
    out = static_cast<std::uint8_t>(n);
  };
  node("can.node_beat_crank", c.can.node_beat_crank);
  node("can.node_carriage", c.can.node_carriage);
  node("can.node_helix", c.can.node_helix);
  if (c.can.node_beat_crank == c.can.node_carriage || c.can.node_beat_crank == c.can.node_helix ||
      c.can.node_carriage == c.can.node_helix) {
    r.fail("can.node_helix", std::to_string(c.can.node_helix), "node ids of the three axes must differ");
  }
  r.number("can.counts_per_rev", c.can.counts_per_rev, positive);
  r.number("can.carriage_counts_per_m", c.can.carriage_counts_per_m, positive);
  const auto ms16 = [&](const char* key, std::uint16_t& out, std::int64_t lo) {
    std::int64_t n = out;
    r.integer(key, n, lo, 60000);
    out = static_cast<std::uint16_t>(n);
  };
  ms16("can.heartbeat_ms", c.can.heartbeat_ms, 10);
  ms16("can.heartbeat_timeout_ms", c.can.heartbeat_timeout_ms, 10);
  ms16("can.sdo_timeout_ms", c.can.sdo_timeout_ms, 10);
  if (c.can.heartbeat_timeout_ms <= c.can.heartbeat_ms || c.can.heartbeat_timeout_ms > 3 * c.can.heartbeat_ms) {
    r.fail("can.heartbeat_timeout_ms", std::to_string(c.can.heartbeat_timeout_ms),
           "must be above heartbeat_ms and at most three heartbeat periods");
  }

  r.string("telemetry.lcm_url", c.telemetry.lcm_url);
  const auto every = [&](const char* key, std::uint32_t& out) {
    std::int64_t n = out;
    r.integer(key, n, 1, 1'000'000);
    out = static_cast<std::uint32_t>(n);
  };
  every("telemetry.status_every", c.telemetry.status_every);
  every("telemetry.axes_every", c.telemetry.axes_every);
  every("telemetry.rt_every", c.telemetry.rt_every);
  r.reject_unknown();

  if (c.beat_force_target_n > 0.0) {
    try {
      const motion::BeatUpDynamics dyn(p.beatup, motion::beatup_masses(p.beatup, beater_kg));
      const double crank_speed_at_beat = dyn.crank_speed_for_beat_force(c.beat_force_target_n);
      // With a speed law the crank is faster (or slower) than the master at the beat: the master runs
      // at the crank speed divided by the law's ratio where the crank reaches the fell.
      double ratio = 1.0;
      if (p.crank_law.kind != motion::CrankLawKind::kConstant) {
        const motion::BeatUp head(p.beatup);
        const double fell_phase = head.warp().fell;
        const motion::CrankLaw speed_law(
            p.crank_law, fell_phase,
            {.size = p.table_size, .interp = p.table_interp, .precision = p.table_precision, .rise = 0.0});
        double m = fell_phase;  // Newton on Φc(m) = m + offset(m) = fell; dΦc/dm ≥ min ratio > 0
        for (int i = 0; i < 50; ++i) {
          const motion::CrankLawExact e = speed_law.exact(m);
          const double step = (m + e.offset - fell_phase) / e.d1;
          m -= step;
          if (std::abs(step) < 1e-14) break;
        }
        ratio = speed_law.exact(m).d1;
      }
      p.crank.velocity = crank_speed_at_beat / ratio;
    } catch (const motion::MotionError& e) {
      r.fail("beatup.beat_force_target_n", std::to_string(c.beat_force_target_n), e.what());
    }
  }

  // Final check: the motion module must be able to build every profile from these numbers.
  try {
    motion::ProfileSet check(c.profile);
  } catch (const motion::MotionError& e) {
    throw ConfigError(source + ": motion profiles cannot be built: " + e.what());
  }
  return c;
}

LoomConfig load_loom_config(const std::string& path) { return parse_loom_config(read_file(path), path); }
LoomConfig default_loom_config() { return parse_loom_config(kDefaultLoomToml, "<embedded default_loom.toml>"); }

}  // namespace loom::firmware
