// See weave_cmd.hpp. The session's steps are the Session's; what is weave's own is its policy: the
// signals, the recipe reload, the simulated weaver, and what it prints and writes about each row.
#include "weave_cmd.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "loom/firmware/carpet_job.hpp"
#include "loom/firmware/job_feed.hpp"
#include "loom/firmware/job_recorder.hpp"
#include "loom/firmware/serve/state_lock.hpp"
#include "loom/firmware/session.hpp"
#include "loom/firmware/sim_weaver.hpp"
#include "loom/motion/angles.hpp"
#include "loom/report/carpet_png.hpp"
#include "loom/report/run_report.hpp"

namespace loom::firmware {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<bool> g_stop_now{false};
std::atomic<bool> g_reload{false};
std::atomic<bool> g_pause{false};
// The first SIGINT/SIGTERM stops at the next hold point (a row's end, between picks or knot cycles); a second
// one stops at once (safe stop: quick stop of every axis, valves hold, counters kept, fault stop_requested).
extern "C" void on_signal(int) {
  if (g_stop.exchange(true)) g_stop_now.store(true);
}
extern "C" void on_hangup(int) {
  g_reload.store(true);
}
extern "C" void on_pause(int) {
  g_pause.store(true);
}
extern "C" void on_resume(int) {
  g_pause.store(false);
}

// What weave resolved from its arguments before anything is built.
struct WeaveInputs {
  Scene scene;
  LoomConfig cfg;
  std::string config_path;       // "" = the embedded default (nothing to reload)
  bool design_from_job = false;  // cfg's recipe design is the carpet job's, not the config file's
};

WeaveInputs resolve_inputs(const WeaveArgs& a) {
  WeaveInputs in;
  in.scene = a.scene.empty() ? default_scene() : load_scene(a.scene);
  in.config_path = a.config;
  if (in.config_path.empty() && !in.scene.config_path.empty()) {
    in.config_path = (std::filesystem::path(a.scene).parent_path() / in.scene.config_path).string();
  }
  in.cfg = in.config_path.empty() ? default_loom_config() : load_loom_config(in.config_path);
  if (a.period_ms > 0.0) {
    in.cfg.run.period_s = a.period_ms * 1e-3;
    rederive_and_check(in.cfg, "--period-ms = " + std::to_string(a.period_ms));
  }
  if (!a.lcm_url.empty()) in.cfg.telemetry.lcm_url = a.lcm_url;
  if (!a.loom_id.empty()) in.cfg.loom_id = a.loom_id;
  return in;
}

// Closed or open loop, and why. The beat regulator acts on measured beats, and beats are measured when the
// machine has a load cell: simulated, when the scene names beat_contact; on the bus, io.load_cell_channel.
void print_beat_regulation(const Machine& m, const Scene& scene, bool simulated_io) {
  const sequencer::SequencerConfig& sc = m.config().sequencer;
  const double v = m.profiles().spec().crank.velocity;
  const bool load_cell =
      simulated_io ? scene.spec.beat_contact.has_value() : m.config().io.wiring.load_cell_channel != 0;
  if (!sc.beat_regulator.enabled || !load_cell) {
    std::printf("  beat force: open loop, %s: every beat at %.2f rad/s\n",
                !sc.beat_regulator.enabled ? "the beat regulator is off"
                : simulated_io             ? "no load cell (the scene does not name beat_contact)"
                                           : "no load cell (io.load_cell_channel = 0)",
                v);
    return;
  }
  sequencer::SweepClock clock;  // the bounds the sequencer derives for this recipe
  const sequencer::BeatRegulatorLimits l = clock.configure(m.profiles(), sc.period_s, sc.beat_regulator,
                                                           0.5 * (sc.beat_force_min_n + sc.beat_force_max_n));
  std::printf(
      "  beat force: closed loop on the load cell, aiming at %.0f N: each beat's peak sets the next beat's "
      "crank speed within %.2f..%.2f rad/s (x%.2f..x%.2f, up to %.1f %% per beat)\n",
      l.target_n, v * l.min_scale, v * l.max_scale, l.min_scale, l.max_scale, 100.0 * l.max_step);
}

void print_header(const Machine& m, const Scene& scene, const WeaveArgs& a) {
  const auto& p = m.profiles();
  const auto& w = p.beatup().warp();
  std::printf("loomctl: loom '%s' (%s), width %.3f m, period %.3g ms, HAL %s%s%s\n",
              m.config().loom_id.c_str(), m.config().source.c_str(), p.spec().width_m,
              m.config().sequencer.period_s * 1e3, a.hal.c_str(), a.hal == "sim" ? ", scene " : ", iface ",
              a.hal == "sim" ? scene.spec.name.c_str() : a.iface.c_str());
  if (a.hal == "sim") {
    std::string effects;
    for (const auto& e : scene.spec.effects) effects += (effects.empty() ? "" : ", ") + e;
    std::printf("  effects: %s\n", effects.c_str());
  }
  std::printf(
      "  beat-up: swing %.2f deg, stroke %.1f mm, warp window %.1f..%.1f deg from park, %d beats/row "
      "at %.1f rad/s, pitch %.1f mm\n",
      motion::deg(p.beatup().dead_centres().swing), p.beatup().stroke_arc_m() * 1e3, motion::deg(w.enter),
      motion::deg(w.exit), p.beats_per_row(), p.spec().crank.velocity, p.pitch_m() * 1e3);
  print_beat_regulation(m, scene, a.hal == "sim" || !m.banner().empty());
  std::printf("  pick: %.2f helix turns in %.3f s (accel limit %.0f rad/s^2, carrier and drive)\n",
              p.spec().width_m / p.spec().helix_lead_m, p.pick().duration(), p.helix_accel_limit());
  for (const std::string& n : m.notes()) std::printf("  CAN: %s\n", n.c_str());
}

// The reporter's side of a weave: what each run event prints, writes and saves. Called between ticks in
// virtual time, on the reporter thread in real time; never from the loop.
class WeaveReporter {
 public:
  WeaveReporter(const WeaveArgs& a, const WeaveInputs& in, Machine& m, ProductionRecord& record,
                std::unique_ptr<report::ReportWriter> writer, const sequencer::Counters& resume,
                std::uint32_t rows)
      : a_(a),
        in_(in),
        m_(m),
        record_(record),
        writer_(std::move(writer)),
        period_(in.cfg.sequencer.period_s),
        target_rows_(resume.rows + rows),
        first_row_(resume.rows),
        picks_at_row_start_(resume.picks),
        progress_bar_(isatty(STDOUT_FILENO) && rows >= 20 && !a.quiet) {}

  void operator()(const RunEvent& e) {
    m_.collect_retired_recipes();
    if (g_reload.exchange(false)) reload_recipe();
    if (e.kind == RunEvent::Kind::kWeaverRequest && m_.knot_program() != nullptr) {
      ++weaver_requests_;
      std::printf("weaver asked: %s\n", sequencer::describe(e.request, *m_.knot_program()).c_str());
      std::fflush(stdout);
    }
    if (e.kind == RunEvent::Kind::kPaused || e.kind == RunEvent::Kind::kResumed) {
      std::printf("%s after row %u, pick %u\n", e.kind == RunEvent::Kind::kPaused ? "paused" : "resumed",
                  e.counters.rows, e.counters.picks);
      std::fflush(stdout);
    }
    if (e.kind == RunEvent::Kind::kRowDone) row_done(e);
    if (recorder_ != nullptr) record_event(e);
    // The magazines before the counters: a cut between the two leaves the levels low (a reload asked
    // early), never high (a slot running dry in a row).
    if (e.kind == RunEvent::Kind::kRowDone || e.kind == RunEvent::Kind::kReloaded) save_magazines(e);
    // Saved after the reload above, so a row that waits for this save starts with the new recipe.
    if (record_.kept()) save(e.counters);
  }

  std::unique_ptr<report::ReportWriter>& writer() { return writer_; }
  void keep_record(JobRecorder* r) { recorder_ = r; }
  const std::string& counters_error() const { return counters_error_; }

  // The rows woven in this run against the hand's time for the same row (the thesis, ch. 6: ~5 min
  // knotting + 2 shedding and picking + 3 beating). A flat weave has no knots: its rows compare with the
  // 5 min of shed, pick and beat. A knotted row compares whole: the machine's time plus whatever the
  // weaver's hands took (knotting every row, or helping the heads).
  void print_speed(const sequencer::Counters& c) const {
    if (rows_ == 0) return;
    const double per_row = machine_s_ / rows_;
    if (in_.cfg.knotting.mode == sequencer::KnottingMode::kNone) {
      std::printf(
          "woven %u rows (total %u): %.2f s per row vs ~%.0f s by hand (shed, pick, beat: %.0fx faster); "
          "picks %u, beats %u\n",
          rows_, c.rows, per_row, report::kManualRowSeconds, report::kManualRowSeconds / per_row, c.picks,
          c.beats);
      return;
    }
    // The same whole-row figure as summary.json's faster_than_manual (report/run_report.cpp).
    const double whole = per_row + weaver_outside_s_ / rows_;
    std::printf(
        "woven %u knotted rows (total %u): %.2f s per whole row (knotting %.2f s by the heads, %.2f s by "
        "the weaver's hands) vs ~%.0f s for the weaver's whole row (%.1fx faster); picks %u, beats %u, knots "
        "%u tied by the heads, %u retried, %u by hand, %u requests to the weaver\n",
        rows_, c.rows, whole, knot_s_ / rows_, weaver_s_ / rows_, report::kManualKnottedRowSeconds,
        report::kManualKnottedRowSeconds / whole, c.picks, c.beats, c.knot.tied, c.knot.retried,
        c.knot.by_hand, weaver_requests_);
    print_yarn(c);
  }

 private:
  double secs(hal::Tick t) const { return static_cast<double>(t) * period_; }

  // The production record is the job's account, not the loop's: a write it refuses is said once and the
  // weave goes on (the counters, saved separately, stay the authority).
  void record_event(const RunEvent& e) {
    try {
      recorder_->on_event(e, m_.knot_program(), in_.cfg.recipe.design.get());
    } catch (const std::exception& ex) {
      std::fprintf(stderr, "loomctl: WARNING: the production record stops here: %s\n", ex.what());
      recorder_ = nullptr;
    }
  }

  // The yarn the rows of this run put into the carpet, per colour (the design's knots of those rows; a
  // retried knot takes its yarn again, on top).
  void print_yarn(const sequencer::Counters& c) const {
    const sequencer::KnotProgram* p = m_.knot_program();
    const design::Design* d = in_.cfg.recipe.design.get();
    if (p == nullptr || d == nullptr || c.rows <= first_row_) return;
    std::vector<std::uint64_t> knots(d->palette().size(), 0);
    for (std::uint32_t r = first_row_; r < c.rows; ++r) {
      for (const std::uint16_t k : d->row(p->design_row(r))) ++knots[k];
    }
    std::string line;
    for (std::size_t i = 0; i < knots.size(); ++i) {
      if (knots[i] == 0) continue;
      line += (line.empty() ? "" : ", ") + d->palette()[i].code + " " + std::to_string(knots[i]);
    }
    std::printf("yarn into the carpet (knots per colour): %s; %llu retried knots took yarn again\n",
                line.c_str(), static_cast<unsigned long long>(retried_));
  }

  // SIGHUP: re-read the recipe (the loom config file) and hand it to the loop for the next row.
  void reload_recipe() {
    try {
      if (in_.config_path.empty())
        throw ConfigError("no --config file to reload (running the embedded default)");
      LoomConfig next = load_loom_config(in_.config_path);
      // Command-line overrides of run settings hold for the reloaded file too.
      next.run.period_s = in_.cfg.run.period_s;
      next.telemetry.lcm_url = in_.cfg.telemetry.lcm_url;
      next.loom_id = in_.cfg.loom_id;
      if (in_.design_from_job) {  // the carpet job's design stays: a recipe reload never changes the carpet
        next.recipe.design = in_.cfg.recipe.design;
        next.recipe.design_file = in_.cfg.recipe.design_file;
      }
      derive_module_configs(next);
      m_.publish_recipe(next);
      std::printf("recipe: %s reloaded; the loom adopts it at the next row\n", in_.config_path.c_str());
    } catch (const ConfigError& ex) {
      std::fprintf(stderr, "loomctl: recipe not reloaded, weaving on with the current one: %s\n", ex.what());
    }
  }

  void row_done(const RunEvent& e) {
    const sequencer::RowStats& r = e.row;
    ++rows_;
    machine_s_ += secs(r.total_ticks);
    knot_s_ += secs(r.knot_ticks);
    retried_ += static_cast<std::uint64_t>(r.knots_retried);
    weaver_s_ += secs(r.knotting_ticks + r.weaver_ticks);
    weaver_outside_s_ += secs(r.knotting_ticks);  // the weaver's own knotting is not in the row's time
    if (writer_) {
      try {
        writer_->add_row(r, e.counters.picks - picks_at_row_start_, secs(e.tick));
      } catch (const std::exception& ex) {
        std::fprintf(stderr, "loomctl: WARNING: report row not written: %s\n", ex.what());
      }
    }
    picks_at_row_start_ = e.counters.picks;
    if (progress_bar_) {
      const int width = 40;
      const int done = static_cast<int>(width * rows_ / a_.rows);
      std::printf("\r[%.*s%*s] %u/%u rows", done, "########################################", width - done,
                  "", rows_, a_.rows);
      if (rows_ == a_.rows) std::printf("\n");
    } else {
      print_row(r);
    }
    std::fflush(stdout);
  }

  void print_row(const sequencer::RowStats& r) const {
    std::printf("row %u/%u: %.2f s (shed %.2f s, pick %.2f s, beat %.2f s), %d beats, %d carriage steps",
                r.row, target_rows_, secs(r.total_ticks), secs(r.shed_ticks), secs(r.pick_ticks),
                secs(r.beat_ticks), r.beats, r.carriage_steps);
    if (r.knotting_ticks > 0) std::printf(", knotted in %.2f s before it", secs(r.knotting_ticks));
    if (r.knots_tied + r.knots_by_hand > 0) {
      std::printf(", %d knots tied in %.2f s (%d retried, %d by hand", r.knots_tied, secs(r.knot_ticks),
                  r.knots_retried, r.knots_by_hand);
      if (r.weaver_ticks > 0) std::printf(", %.2f s waiting for the weaver", secs(r.weaver_ticks));
      std::printf(")");
    }
    if (r.force_measured) {
      std::printf(", peak beat force min/mean/max %.1f/%.1f/%.1f N", r.force_min_n, r.force_mean_n,
                  r.force_max_n);
    }
    std::printf("\n");
  }

  // A failed save is tried again (retry_save), as the service does: a disk that frees up lets the loom
  // weave on; one that does not ends in counters_not_saved at the row's end, or once a knot cycle's
  // write-ahead has waited timing.row_save_timeout_s — never a loom standing mid-row for ever.
  void save_magazines(const RunEvent& e) {
    try {
      record_.save_magazines(e);
    } catch (const std::exception& ex) {
      std::fprintf(stderr,
                   "loomctl: WARNING: the magazines' levels were not saved (a restart would take them as "
                   "of the last saved row): %s\n",
                   ex.what());
    }
  }

  void save(const sequencer::Counters& c) {
    try {
      record_.save(c);
      unsaved_.reset();
      counters_error_.clear();  // on disk again: nothing lags
    } catch (const std::exception& ex) {
      if (counters_error_.empty()) {
        std::fprintf(stderr,
                     "loomctl: counters not saved: %s; retrying (the loom stops with counters_not_saved at "
                     "the row's end, or when a knot cycle has waited %.3g s for it)\n",
                     ex.what(), in_.cfg.sequencer.row_save_timeout_s);
      }
      counters_error_ = ex.what();
      unsaved_ = c;
    }
  }

 public:
  // The runner's poll (between ticks, every 100 ms of machine time in virtual time): a failed save again,
  // paced in real time at one try per half second of machine time — several within the save's deadline
  // (timing.row_save_timeout_s), whatever --pace says.
  void retry_save() {
    if (!unsaved_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_retry_ < retry_every_) return;
    last_retry_ = now;
    try {
      record_.save(*unsaved_);
      unsaved_.reset();
      counters_error_.clear();
      std::fprintf(stderr, "loomctl: counters saved again (rows %u)\n",
                   record_.row_saves()->rows_on_disk.load());
    } catch (const std::exception&) {
      // Still failing: the first failure was said; the sequencer's deadline decides.
    }
  }

 private:
  const WeaveArgs& a_;
  const WeaveInputs& in_;
  Machine& m_;
  ProductionRecord& record_;
  std::unique_ptr<report::ReportWriter> writer_;  // streams each row to disk (constant memory)
  const double period_;
  const std::uint32_t target_rows_;
  const std::uint32_t first_row_;  // the counters' rows when this run began
  std::uint32_t picks_at_row_start_;
  const bool progress_bar_;  // a terminal only; logs get the per-row lines
  std::uint32_t rows_ = 0;   // rows woven in this run
  double machine_s_ = 0.0;
  double knot_s_ = 0.0, weaver_s_ = 0.0;  // the heads' knotting, and the weaver's hands, in those rows
  std::uint64_t retried_ = 0;             // knots the heads retried in those rows
  JobRecorder* recorder_ = nullptr;       // the carpet job's production record (weave --state-dir)
  double weaver_outside_s_ = 0.0;
  std::uint32_t weaver_requests_ = 0;
  std::string counters_error_;                  // why the last save failed
  std::optional<sequencer::Counters> unsaved_;  // the counters a failed save could not write yet
  std::chrono::steady_clock::time_point last_retry_{};
  std::chrono::steady_clock::duration retry_every_{};  // wall time between tries (0 in virtual time)

 public:
  void pace_retries(bool realtime, double pace) {
    const double machine_s = std::min(0.5, in_.cfg.sequencer.row_save_timeout_s / 5.0);
    retry_every_ = realtime ? std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(machine_s / std::max(pace, 1e-3)))
                            : std::chrono::steady_clock::duration::zero();
  }
};

std::unique_ptr<report::ReportWriter> open_report(const WeaveArgs& a, const WeaveInputs& in, bool hardware) {
  if (a.report.empty()) return nullptr;
  report::RunHeader rh;
  rh.loom_id = in.cfg.loom_id;
  rh.scene = hardware ? "socketcan:" + a.iface : in.scene.spec.name;
  rh.effects = hardware ? std::vector<std::string>{} : in.scene.spec.effects;
  rh.period_s = in.cfg.sequencer.period_s;
  rh.beat_force_min_n = in.cfg.sequencer.beat_force_min_n;
  rh.beat_force_max_n = in.cfg.sequencer.beat_force_max_n;
  rh.manual_row_s = in.cfg.knotting.mode == sequencer::KnottingMode::kNone ? report::kManualRowSeconds
                                                                           : report::kManualKnottedRowSeconds;
  try {
    return std::make_unique<report::ReportWriter>(a.report, rh);
  } catch (const std::exception& e) {
    throw SessionError(kExitBadInput, "--report " + a.report + ": " + e.what());
  }
}

// The carpet the simulated heads knotted, beside the report, compared with the design knot for knot.
void write_carpet(const WeaveArgs& a, const LoomConfig& cfg, Machine& m) {
  const sim_hal::SimKnotter* k = m.sim().knotter();
  if (k == nullptr || a.report.empty()) return;
  const std::string png = a.report + "/carpet.png";
  try {
    // Every row the counters say was woven since the carpet began is compared, knotted or not.
    const std::uint32_t woven = m.sequencer().counters().rows;
    const int rows_woven = woven > k->first_row() ? static_cast<int>(woven - k->first_row()) : 0;
    const report::CarpetCheck cc =
        report::write_carpet_png(*k, *m.knot_program(), *cfg.recipe.design, k->first_row(), png, rows_woven);
    std::printf(
        "carpet: %s: %d rows from production row %u (design row %d), %d knots (%d by hand); %s\n",
        png.c_str(), cc.rows, k->first_row(), m.knot_program()->design_row(k->first_row()) + 1, cc.knots,
        cc.by_hand,
        cc.equal()
            ? "equals the design knot for knot"
            : ("DIFFERS from the design: " + std::to_string(cc.missing) + " missing, " +
               std::to_string(cc.wrong) + " wrong colour, " + std::to_string(cc.doubled) + " tied twice" +
               (cc.unrecorded == 0
                    ? std::string()
                    : ", " + std::to_string(cc.unrecorded) + " tied beyond the simulator's record of " +
                          std::to_string(k->capacity_rows()) + " rows (scene knotter.carpet_rows)"))
                  .c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loomctl: %s\n", e.what());
  }
}

void print_fault(const FaultReport& f, double period, const sequencer::Counters& c) {
  std::string note = f.stopped_note();
  if (const std::string w = f.where(); !w.empty()) note = w + (note.empty() ? "" : " " + note);
  std::printf(
      "FAULT %s (code 0x%04X%s%s%s%s, device code 0x%04X) at t=%.3f s%s%s: %s; rows completed %u, picks %u, "
      "beats %u\n",
      f.name(), f.code(), f.axis.empty() ? "" : ", axis ", f.axis.c_str(), f.sensor >= 0 ? ", sensor " : "",
      f.sensor_name(), f.device_code, static_cast<double>(f.tick) * period, note.empty() ? "" : " ",
      note.c_str(), sequencer::fault_text(f.fault), c.rows, c.picks, c.beats);
}

// Where a weave keeps its production state: the files given one by one (--counters, --sim-state), or
// serve's state directory (locked as serve locks it, so the two never weave one loom's state at once).
struct WeaveState {
  std::string counters, sim_state;
  std::unique_ptr<serve::StateDirLock> lock;
};

WeaveState open_state_dir(const WeaveArgs& a, const WeaveInputs& in) {
  WeaveState st;
  if (a.state_dir.empty()) {
    st.counters = a.counters;
    st.sim_state = a.sim_state;
    return st;
  }
  std::error_code ec;
  if (!std::filesystem::is_directory(a.state_dir, ec)) {
    throw ConfigError("--state-dir " + a.state_dir + ": not a directory");
  }
  try {
    st.lock = std::make_unique<serve::StateDirLock>(a.state_dir, in.cfg.loom_id, "(loomctl weave)");
  } catch (const std::exception& e) {
    throw SessionError(kExitNotArmed, std::string("refusing to arm: ") + e.what());
  }
  st.counters = a.state_dir + "/counters.json";
  if (a.hal == "sim") st.sim_state = a.state_dir + "/sim-state.bin";
  return st;
}

int weave(const WeaveArgs& a, const Say& say) {
  // ---- build and arm: everything that can fail on input fails here, before anything moves ----
  SessionOptions so = SessionOptions::from_command_line(a.hal, a.iface, a.io, a.pace);
  so.realtime = a.realtime;
  so.allow_degraded = a.allow_degraded;
  WeaveInputs in = resolve_inputs(a);
  const WeaveState st = open_state_dir(a, in);
  if (a.knotting_s > 0.0 && (so.hardware() || !in.cfg.sequencer.knotting)) {
    char value[32];
    std::snprintf(value, sizeof value, "%g", a.knotting_s);
    throw ConfigError(std::string("--knotting-s = ") + value + ": " +
                      (so.hardware() ? "the simulated weaver exists in simulation only (on a loom the weaver "
                                       "presses the pedal)"
                                     : "the loom has no weaver's knotting (set knotting.mode = \"weaver\")"));
  }
  ProductionRecord record(st.counters, in.cfg);
  const sequencer::Counters resume = record.load();
  CarpetJob* job = nullptr;
  if (!a.state_dir.empty()) {
    record.keep_magazines(in.cfg);
    record.weave_jobs(std::make_unique<CarpetJob>(a.state_dir));
    job = record.jobs();
    if (job != nullptr) {
      in.cfg = job->config_for(in.cfg);  // the job's design, checked against its hash and the loom
      in.design_from_job = true;
    } else if (auto done = CarpetJob(a.state_dir).carpet_done_id(); done != 0) {
      throw ConfigError("--state-dir " + a.state_dir + ": no carpet job to weave: job " +
                        std::to_string(done) +
                        " is carpet_done (cut it off, tie the fringe warp) and none is queued: add the next "
                        "one with loomctl job add DESIGN --state-dir " +
                        a.state_dir);
    }
  }
  std::uint32_t rows = a.rows;
  if (job != nullptr) {
    const std::uint64_t left = job->rows_left();
    rows = static_cast<std::uint32_t>(std::min<std::uint64_t>(a.rows_given ? a.rows : left, left));
  }
  // `--rows N` weaves N more rows after the ones already counted; the sum must stay a count.
  if (static_cast<std::uint64_t>(resume.rows) + rows > UINT32_MAX) {
    throw ConfigError("--rows = " + std::to_string(rows) + ": after row " + std::to_string(resume.rows) +
                      " this would pass the row counter's range (4294967295); counters are never wrapped");
  }
  record.prove_writable(resume);  // a loom that must count and cannot refuses to arm
  const std::uint64_t design_rows = record.activate_design(resume.rows);
  record.begin_session(resume);
  prepare_realtime(so, say);

  Session session(so, say);
  MachineOptions mo;
  mo.telemetry = !a.no_telemetry;
  mo.rows = resume.rows + rows;  // the sequencer counts absolute rows; weave `rows` more
  mo.sim_state_path = st.sim_state;
  mo.await_row_saved = record.kept();  // no row starts before the one before it is on disk
  mo.design_rows_done = design_rows;
  if (job != nullptr) mo.carpet_began = carpet_began(resume.rows, design_rows);
  Machine& machine = session.build(in.cfg, in.scene, mo, resume);
  const auto levels = record.load_magazines(say);
  if (levels) machine.sequencer().restore_magazines(*levels);
  if (!a.quiet) print_header(machine, in.scene, a);
  if (resume.rows > 0) {
    std::printf("  resuming after row %u (picks %u, beats %u)\n", resume.rows, resume.picks, resume.beats);
  }
  // weave runs at the machine: the next queued job starts here, as a start button would start it — once
  // everything that can refuse the input has passed.
  if (job != nullptr) {
    const bool started = job->start(resume.rows);
    std::printf("  %s%s\n", job->describe().c_str(), started ? " (started now)" : "");
  }
  // The job for the weaver's panel (telemetry JOB and CARPET), as serve publishes it.
  std::unique_ptr<JobFeed> job_feed;
  if (job != nullptr && !a.no_telemetry) {
    job_feed = std::make_unique<JobFeed>(a.state_dir, in.cfg.telemetry.lcm_url, in.cfg.loom_id);
    job_feed->armed(machine);
  }
  if (const auto& d = in.cfg.recipe.design; d && !a.quiet) {
    std::printf("  %s%s\n", design_position(*d, design_rows).c_str(),
                record.kept() ? "" : " (no --counters: the row reached is not remembered)");
  }
  if (!a.quiet) record.say_yarn_forecast(machine.knot_program(), levels, resume.rows, rows, say);

  // ---- run ----
  WeaveReporter reporter(a, in, machine, record, open_report(a, in, so.hardware()), resume, rows);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGHUP, on_hangup);
  std::signal(SIGUSR1, on_pause);  // pause at the next safe point (before a shed change)
  std::signal(SIGUSR2, on_resume);
  sequencer::Sequencer& seq = machine.sequencer();
  seq.request_start();
  RunOptions ro = session.run_options(&record);
  ro.grace_ticks = static_cast<hal::Tick>(0.2 / ro.period_s);
  ro.stop_flag = &g_stop;
  ro.stop_now_flag = &g_stop_now;
  ro.pause_flag = &g_pause;
  if (ro.sim_weaver != nullptr) ro.sim_weaver->knot_rows_after(a.knotting_s);
  reporter.pace_retries(ro.realtime, ro.pace);
  ro.reporter_poll = [&reporter, &job_feed] {
    reporter.retry_save();
    if (job_feed) job_feed->poll();
  };
  // The job's production record (production.sqlite in the state directory).
  std::unique_ptr<JobRecorder> job_record;
  if (job != nullptr) {
    try {
      job_record =
          std::make_unique<JobRecorder>(a.state_dir, job->job(), resume.rows, ro.period_s, !ro.realtime);
      reporter.keep_record(job_record.get());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "loomctl: WARNING: no production record for this run: %s\n", e.what());
    }
  }
  const RunResult res = session.run(ro, [&reporter, &job_feed](const RunEvent& e) {
    reporter(e);
    if (job_feed) job_feed->on_event(e);
  });
  const bool carpet_done = record.take_carpet_done();
  if (job_record) {
    try {
      job_record->finish(res.ticks, carpet_done);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "loomctl: WARNING: the production record's last commit failed: %s\n", e.what());
    }
  }

  // ---- report ----
  const sequencer::Counters& c = seq.counters();
  const std::optional<FaultReport> fault = session.fault();
  const double period = ro.period_s;
  report::RunEnd summary;
  summary.counters = c;
  summary.machine_s = static_cast<double>(res.ticks) * period;
  summary.wall_s = res.wall_s;
  if (fault) {
    summary.fault = report::FaultSummary{fault->name(),
                                         fault->code(),
                                         fault->axis,
                                         fault->device_code,
                                         static_cast<double>(fault->tick) * period,
                                         sequencer::fault_name(fault->stopped_by),
                                         sequencer::fault_text(fault->fault)};
  }
  if (!so.hardware()) write_carpet(a, in.cfg, machine);
  if (auto& writer = reporter.writer()) {
    try {
      writer->finish(summary);
      std::printf("report: %s/summary.json, beat_force.svg, row_timeline.svg\n", a.report.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "loomctl: report not written: %s\n", e.what());
    }
  }
  if (fault) {
    print_fault(*fault, period, c);
    if (fault->fault == sequencer::Fault::kCountersNotSaved && !reporter.counters_error().empty()) {
      std::printf("  the save failed: %s\n", reporter.counters_error().c_str());
    }
    return kExitFault;
  }
  if (!reporter.counters_error().empty()) {
    std::printf("FAULT counters_not_saved: %s; rows completed %u, picks %u, beats %u (not on disk)\n",
                reporter.counters_error().c_str(), c.rows, c.picks, c.beats);
    return kExitFault;
  }
  reporter.print_speed(c);
  if (carpet_done) {
    std::printf(
        "carpet done: the job's last row is woven (rows %u): cut the carpet off and tie the fringe warp; "
        "the next queued job starts at the machine (loomctl job list --state-dir %s)\n",
        c.rows, a.state_dir.c_str());
  }
  return kExitOk;
}

}  // namespace

int run_weave(const WeaveArgs& a) {
  const Say say = console_say("loomctl");
  return exit_code_of(say, [&] { return weave(a, say); });
}

}  // namespace loom::firmware
