// loomctl — the loom controller. `loomctl weave` configures a loom (embedded default, --config or a
// scene's config), picks the HAL (simulated in virtual time by default, or SocketCAN drives in real
// time), and runs the fixed-rate loop until the rows are woven or a fault stops the machine.
// Exit codes: 0 rows woven, 2 bad input (nothing started), 3 ended in a fault, 4 hardware not armed.
#include <CLI/CLI.hpp>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <tuple>

#include "loom/drivers/bus_load.hpp"
#include "loom/firmware/carpet_png.hpp"
#include "loom/firmware/config.hpp"
#include "loom/firmware/counter_store.hpp"
#include "loom/firmware/design_book.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/firmware/serve/commands.hpp"
#include "loom/motion/angles.hpp"
#include "loom/report/run_report.hpp"
#include "check_cmd.hpp"
#include "commission_cmd.hpp"
#include <unistd.h>

using namespace loom;

namespace {

constexpr int kExitOk = 0, kExitBadInput = 2, kExitFault = 3, kExitNotArmed = 4;
std::atomic<bool> g_stop{false};
std::atomic<bool> g_reload{false};
std::atomic<bool> g_stop_now{false};
// The first SIGINT/SIGTERM stops at the end of the row; a second one stops at once (safe stop: quick
// stop of every axis, valves hold, counters kept, fault stop_requested).
extern "C" void on_signal(int) {
  if (g_stop.exchange(true)) g_stop_now.store(true);
}
extern "C" void on_hangup(int) { g_reload.store(true); }
std::atomic<bool> g_pause{false};
extern "C" void on_pause(int) { g_pause.store(true); }
extern "C" void on_resume(int) { g_pause.store(false); }

struct WeaveArgs {
  std::string config, scene, hal = "sim", iface, counters, lcm_url, loom_id, report, sim_state, io;
  std::uint32_t rows = 3;
  double period_ms = 0.0;
  double pace = 1.0;
  double knotting_s = 0.0;  // sim: a simulated weaver says "row knotted" this long after each wait begins
  bool realtime = false, allow_degraded = false, no_telemetry = false, quiet = false;
};

void print_header(const firmware::Machine& m, const firmware::Scene& scene, const WeaveArgs& a) {
  const auto& p = m.profiles();
  const auto& w = p.beatup().warp();
  std::printf("loomctl: loom '%s' (%s), width %.3f m, period %.3g ms, HAL %s%s%s\n", m.config().loom_id.c_str(),
              m.config().source.c_str(), p.spec().width_m, m.config().sequencer.period_s * 1e3, a.hal.c_str(),
              a.hal == "sim" ? ", scene " : ", iface ", a.hal == "sim" ? scene.spec.name.c_str() : a.iface.c_str());
  if (a.hal == "sim") {
    std::string effects;
    for (const auto& e : scene.spec.effects) effects += (effects.empty() ? "" : ", ") + e;
    std::printf("  effects: %s\n", effects.c_str());
  }
  std::printf("  beat-up: swing %.2f deg, stroke %.1f mm, warp window %.1f..%.1f deg from park, %d beats/row "
              "at %.1f rad/s, pitch %.1f mm\n",
              motion::deg(p.beatup().dead_centres().swing), p.beatup().stroke_arc_m() * 1e3, motion::deg(w.enter),
              motion::deg(w.exit), p.beats_per_row(), p.spec().crank.velocity, p.pitch_m() * 1e3);
  std::printf("  pick: %.2f helix turns in %.3f s (accel limit %.0f rad/s^2, carrier and drive)\n",
              p.spec().width_m / p.spec().helix_lead_m, p.pick().duration(), p.helix_accel_limit());
  for (const std::string& n : m.notes()) std::printf("  CAN: %s\n", n.c_str());
}

int weave(const WeaveArgs& a) {
  // ---- configure: everything that can fail on input fails here, before anything moves ----
  firmware::Scene scene;
  firmware::LoomConfig cfg;
  std::string config_path;
  sequencer::Counters resume{};
  std::unique_ptr<firmware::CounterStore> store;
  std::unique_ptr<firmware::DesignBook> book;  // with --counters and a design: the row each design reached
  std::uint64_t design_rows = 0;                 // rows of the recipe's design woven before this run
  try {
    scene = a.scene.empty() ? firmware::default_scene() : firmware::load_scene(a.scene);
    config_path = a.config;
    if (config_path.empty() && !scene.config_path.empty()) {
      config_path = (std::filesystem::path(a.scene).parent_path() / scene.config_path).string();
    }
    cfg = config_path.empty() ? firmware::default_loom_config() : firmware::load_loom_config(config_path);
    if (a.period_ms > 0.0) {
      cfg.run.period_s = a.period_ms * 1e-3;
      firmware::rederive_and_check(cfg, "--period-ms = " + std::to_string(a.period_ms));
    }
    if (!a.lcm_url.empty()) cfg.telemetry.lcm_url = a.lcm_url;
    if (!a.loom_id.empty()) cfg.loom_id = a.loom_id;
    if (!a.counters.empty()) {
      store = std::make_unique<firmware::CounterStore>(a.counters);
      if (auto c = store->load()) resume = *c;
      if (resume.picks_in_row > cfg.recipe.picks_per_row) {
        throw firmware::ConfigError(a.counters + ": picks_in_row = " + std::to_string(resume.picks_in_row) +
                                    " but the recipe has " + std::to_string(cfg.recipe.picks_per_row) +
                                    " pick(s) per row: these counters are not this loom's");
      }
    }
    // `--rows N` weaves N more rows after the ones already counted; the sum must stay a count.
    if (static_cast<std::uint64_t>(resume.rows) + a.rows > UINT32_MAX) {
      throw firmware::ConfigError("--rows = " + std::to_string(a.rows) + ": after row " + std::to_string(resume.rows) +
                                  " this would pass the row counter's range (4294967295); counters are never wrapped");
    }
    if (store) {
      // Refuse to arm when the counters cannot be kept: prove the file writable before anything moves.
      try {
        store->save(resume);
      } catch (const std::exception& ex) {
        throw firmware::ConfigError(std::string("counters file cannot be written, refusing to arm: ") + ex.what());
      }
      // The row each design has reached is kept beside the counters (designs.json).
      if (cfg.recipe.design) {
        const auto dir = std::filesystem::path(a.counters).parent_path();
        book = std::make_unique<firmware::DesignBook>((dir.empty() ? std::string("designs.json") : (dir / "designs.json").string()));
        try {
          design_rows = book->activate(cfg.recipe.design->name(), resume.rows);
        } catch (const firmware::ConfigError&) {
          throw;
        } catch (const std::exception& ex) {
          throw firmware::ConfigError(std::string("design book cannot be written, refusing to arm: ") + ex.what());
        }
      }
    }
  } catch (const firmware::ConfigError& e) {
    std::fprintf(stderr, "loomctl: %s\n", e.what());
    return kExitBadInput;
  }

  const bool hardware = a.hal == "socketcan";
  const bool realtime = hardware || a.realtime;
  if (a.knotting_s > 0.0 && (hardware || !cfg.sequencer.knotting)) {
    std::fprintf(stderr, "loomctl: --knotting-s = %g: %s\n", a.knotting_s,
                 hardware ? "the simulated weaver exists in simulation only (on a loom the weaver presses the pedal)"
                          : "the loom has no weaver's knotting (set knotting.mode = \"weaver\")");
    return kExitBadInput;
  }
  if (hardware) {
    const firmware::RtSetup rt = firmware::setup_realtime(80);
    if (!rt.ok()) {
      if (!a.allow_degraded) {
        std::fprintf(stderr,
                     "loomctl: refusing to arm: real-time setup failed (%s) — fix privileges/limits or pass "
                     "--allow-degraded to run without real-time guarantees\n",
                     rt.problems.c_str());
        return kExitNotArmed;
      }
      std::fprintf(stderr, "loomctl: WARNING: RUNNING DEGRADED: %s timing is not guaranteed\n", rt.problems.c_str());
    }
  }

  firmware::MachineOptions mo;
  mo.hal = hardware ? firmware::HalKind::kSocketCan : firmware::HalKind::kSim;
  mo.iface = a.iface;
  mo.telemetry = !a.no_telemetry;
  mo.lossless_telemetry = !realtime;  // real time never waits on telemetry: drop and count
  mo.rows = resume.rows + a.rows;  // the sequencer counts absolute rows; weave `rows` more
  mo.sim_state_path = a.sim_state;
  mo.await_row_saved = store != nullptr;  // no row starts before the one before it is on disk
  mo.design_rows_done = design_rows;
  if (!a.io.empty()) mo.io = a.io == "simulated" ? firmware::IoKind::kSimulated : firmware::IoKind::kCan;
  std::unique_ptr<firmware::Machine> machine;
  try {
    machine = std::make_unique<firmware::Machine>(cfg, scene, mo, resume);
  } catch (const firmware::ConfigError& e) {
    std::fprintf(stderr, "loomctl: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loomctl: cannot arm: %s\n", e.what());
    return kExitNotArmed;
  }
  if (!machine->banner().empty()) std::fprintf(stderr, "loomctl: WARNING: %s\n", machine->banner().c_str());
  if (!a.quiet) print_header(*machine, scene, a);
  if (resume.rows > 0) std::printf("  resuming after row %u (picks %u, beats %u)\n", resume.rows, resume.picks, resume.beats);
  if (const auto& d = cfg.recipe.design; d && !a.quiet) {
    const auto pos = design::position_after(*d, design_rows);
    std::printf("  design %s (%d x %d knots): row %d to knot next%s\n", d->name().c_str(), d->width(), d->height(),
                pos.row + 1, book ? "" : " (no --counters: the row reached is not remembered)");
  }

  // ---- run ----
  const double period = cfg.sequencer.period_s;
  const std::uint32_t target_rows = resume.rows + a.rows;
  double machine_s_rows = 0.0;
  double knot_s_rows = 0.0, weaver_s_rows = 0.0;  // the heads' knotting, and the weaver's hands, in those rows
  double weaver_outside_s_rows = 0.0;
  std::uint32_t rows_this_run = 0;
  std::uint32_t weaver_requests = 0;
  const auto secs = [&](hal::Tick t) { return static_cast<double>(t) * period; };
  // A progress bar on long runs (a terminal only; logs get the per-row lines).
  const bool progress_bar = isatty(STDOUT_FILENO) && a.rows >= 20 && !a.quiet;
  // The report streams each row to disk as it completes (constant memory, however many rows).
  std::unique_ptr<report::ReportWriter> report_writer;
  if (!a.report.empty()) {
    report::RunHeader rh;
    rh.loom_id = cfg.loom_id;
    rh.scene = hardware ? "socketcan:" + a.iface : scene.spec.name;
    rh.effects = hardware ? std::vector<std::string>{} : scene.spec.effects;
    rh.period_s = period;
    rh.beat_force_min_n = cfg.sequencer.beat_force_min_n;
    rh.beat_force_max_n = cfg.sequencer.beat_force_max_n;
    try {
      report_writer = std::make_unique<report::ReportWriter>(a.report, rh);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "loomctl: --report %s: %s\n", a.report.c_str(), e.what());
      return kExitBadInput;
    }
  }
  std::uint32_t picks_at_row_start = resume.picks;
  std::string counters_error;  // why the last save failed: the sequencer stops at the row boundary
  firmware::RowSaves row_saves;
  const auto on_event = [&](const firmware::RunEvent& e) {
    // SIGHUP: re-read the recipe (the loom config file) and hand it to the loop for the next row.
    machine->collect_retired_recipes();
    if (g_reload.exchange(false)) {
      try {
        if (config_path.empty()) throw firmware::ConfigError("no --config file to reload (running the embedded default)");
        firmware::LoomConfig next = firmware::load_loom_config(config_path);
        // Command-line overrides of run settings hold for the reloaded file too.
        next.run.period_s = cfg.run.period_s;
        next.telemetry.lcm_url = cfg.telemetry.lcm_url;
        next.loom_id = cfg.loom_id;
        firmware::derive_module_configs(next);
        machine->publish_recipe(next);
        std::printf("recipe: %s reloaded; the loom adopts it at the next row\n", config_path.c_str());
      } catch (const firmware::ConfigError& ex) {
        std::fprintf(stderr, "loomctl: recipe not reloaded, weaving on with the current one: %s\n", ex.what());
      }
    }
    if (e.kind == firmware::RunEvent::Kind::kWeaverRequest && machine->knot_program() != nullptr) {
      ++weaver_requests;
      std::printf("weaver asked: %s\n", sequencer::describe(e.request, *machine->knot_program()).c_str());
      std::fflush(stdout);
    }
    if (e.kind == firmware::RunEvent::Kind::kPaused || e.kind == firmware::RunEvent::Kind::kResumed) {
      std::printf("%s after row %u, pick %u\n", e.kind == firmware::RunEvent::Kind::kPaused ? "paused" : "resumed",
                  e.counters.rows, e.counters.picks);
      std::fflush(stdout);
    }
    if (e.kind == firmware::RunEvent::Kind::kRowDone) {
      const auto& r = e.row;
      ++rows_this_run;
      machine_s_rows += secs(r.total_ticks);
      knot_s_rows += secs(r.knot_ticks);
      weaver_s_rows += secs(r.knotting_ticks + r.weaver_ticks);
      weaver_outside_s_rows += secs(r.knotting_ticks);  // the weaver's own knotting is not in the row's time
      if (report_writer) {
        try {
          report_writer->add_row(r, e.counters.picks - picks_at_row_start, secs(e.tick));
        } catch (const std::exception& ex) {
          std::fprintf(stderr, "loomctl: WARNING: report row not written: %s\n", ex.what());
        }
      }
      picks_at_row_start = e.counters.picks;
      if (progress_bar) {
        const int width = 40;
        const int done = static_cast<int>(width * rows_this_run / a.rows);
        std::printf("\r[%.*s%*s] %u/%u rows", done, "########################################", width - done, "",
                    rows_this_run, a.rows);
        if (rows_this_run == a.rows) std::printf("\n");
      } else {
        std::printf("row %u/%u: %.2f s (shed %.2f s, pick %.2f s, beat %.2f s), %d beats, %d carriage steps", r.row,
                    target_rows, secs(r.total_ticks), secs(r.shed_ticks), secs(r.pick_ticks), secs(r.beat_ticks),
                    r.beats, r.carriage_steps);
        if (r.knotting_ticks > 0) std::printf(", knotted in %.2f s before it", secs(r.knotting_ticks));
        if (r.knots_tied + r.knots_by_hand > 0) {
          std::printf(", %d knots tied in %.2f s (%d retried, %d by hand", r.knots_tied, secs(r.knot_ticks), r.knots_retried,
                      r.knots_by_hand);
          if (r.weaver_ticks > 0) std::printf(", %.2f s waiting for the weaver", secs(r.weaver_ticks));
          std::printf(")");
        }
        if (r.force_measured) {
          std::printf(", peak beat force min/mean/max %.1f/%.1f/%.1f N", r.force_min_n, r.force_mean_n, r.force_max_n);
        }
        std::printf("\n");
      }
      std::fflush(stdout);
    }
    // Saved after the reload above, so a row that waits for this save starts with the new recipe.
    if (store) {
      try {
        store->save(e.counters);
        if (book) book->record(e.counters.rows);  // after the counters: a cut between lags, never leads
        row_saves.saved(e.counters.rows);
        row_saves.saved_knots(e.counters.rows, e.counters.knot.cycles_started);
      } catch (const std::exception& ex) {
        // Weaving on without a durable count would lose work at the next power cut: the sequencer
        // stops at the row boundary (a safe point) with counters_not_saved, keeping its counters.
        if (counters_error.empty()) {
          std::fprintf(stderr, "loomctl: counters not saved: %s; stopping at the end of the row\n", ex.what());
        }
        counters_error = ex.what();
        row_saves.failed();
      }
    }
  };
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGHUP, on_hangup);
  std::signal(SIGUSR1, on_pause);   // pause at the next safe point (before a shed change)
  std::signal(SIGUSR2, on_resume);
  auto& seq = machine->sequencer();
  seq.request_start();
  firmware::RunOptions ro;
  ro.period_s = period;
  ro.realtime = realtime;
  ro.pace = hardware ? 1.0 : a.pace;
  ro.grace_ticks = static_cast<hal::Tick>(0.2 / period);
  ro.stop_flag = &g_stop;
  ro.stop_now_flag = &g_stop_now;
  ro.row_saves = store ? &row_saves : nullptr;
  ro.simulated_knotting_s = a.knotting_s;
  if (machine->knot_program() != nullptr && !hardware) {
    ro.weaver_sink = firmware::Machine::simulated_weaver_sink;
    ro.weaver_sink_ctx = machine.get();
  }
  ro.pause_flag = &g_pause;
  ro.require_fifo = hardware && !a.allow_degraded;
  ro.overrun_stop_after = hardware ? cfg.run.overrun_stop_after : 0;
  const firmware::RunResult res = firmware::run_loop(machine->loop(), seq, ro, on_event);
  if (auto* tm = machine->telemetry()) tm->stop();
  if (res.end == firmware::RunResult::End::kError) {
    std::fprintf(stderr, "loomctl: refusing to run: %s\n", res.error.c_str());
    return kExitNotArmed;
  }

  // ---- report ----
  const double machine_s = static_cast<double>(res.ticks) * period;
  std::printf("%s\n", firmware::describe_run(res, ro).c_str());
  const auto& c = seq.counters();
  report::RunEnd summary;
  summary.counters = c;
  summary.machine_s = machine_s;
  summary.wall_s = res.wall_s;
  if (seq.state() == sequencer::State::kFault) {
    const sequencer::Fault f = seq.first_fault();
    summary.fault = report::FaultSummary{
        sequencer::fault_name(f), sequencer::fault_code(f),
        seq.fault_axis() >= 0 ? seq.axes().name(static_cast<std::size_t>(seq.fault_axis())) : "", seq.fault_detail(),
        secs(seq.fault_tick()), sequencer::fault_name(seq.stopped_by()), sequencer::fault_text(f)};
  }
  // The carpet the simulated heads knotted, beside the report, compared with the design knot for knot.
  if (const sim_hal::SimKnotter* k = machine->sim().knotter(); k != nullptr && !hardware && !a.report.empty()) {
    const std::string png = a.report + "/carpet.png";
    try {
      const firmware::CarpetCheck cc = firmware::write_carpet_png(*k, *machine->knot_program(), *cfg.recipe.design, k->first_row(), png);
      std::printf("carpet: %s: %d rows from production row %u (design row %d), %d knots (%d by hand); %s\n", png.c_str(),
                  cc.rows, k->first_row(), machine->knot_program()->design_row(k->first_row()) + 1, cc.knots, cc.by_hand,
                  cc.equal() ? "equals the design knot for knot"
                             : ("DIFFERS from the design: " + std::to_string(cc.missing) + " missing, " +
                                std::to_string(cc.wrong) + " wrong colour, " + std::to_string(cc.doubled) + " tied twice")
                                   .c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "loomctl: %s\n", e.what());
    }
  }
  if (report_writer) {
    try {
      report_writer->finish(summary);
      std::printf("report: %s/summary.json, beat_force.svg, row_timeline.svg\n", a.report.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "loomctl: report not written: %s\n", e.what());
    }
  }
  if (seq.state() == sequencer::State::kFault) {
    const sequencer::Fault f = seq.first_fault();
    const std::string stopped = seq.stopped_by() == f ? std::string()
                                                        : std::string(" (motion stopped on ") +
                                                              sequencer::fault_name(seq.stopped_by()) + ")";
    const int sensor = seq.fault_sensor();
    std::printf("FAULT %s (code 0x%04X%s%s%s%s, device code 0x%04X) at t=%.3f s%s: %s; rows completed %u, picks %u, "
                "beats %u\n",
                sequencer::fault_name(f), sequencer::fault_code(f), seq.fault_axis() >= 0 ? ", axis " : "",
                seq.fault_axis() >= 0 ? seq.axes().name(static_cast<std::size_t>(seq.fault_axis())) : "",
                sensor >= 0 ? ", sensor " : "",
                sensor >= 0 ? hal::safety_sensor_name(static_cast<hal::SafetySensor>(sensor)) : "",
                seq.fault_detail(), secs(seq.fault_tick()), stopped.c_str(), sequencer::fault_text(f), c.rows,
                c.picks, c.beats);
    if (f == sequencer::Fault::kCountersNotSaved && !counters_error.empty()) {
      std::printf("  the save failed: %s\n", counters_error.c_str());
    }
    return kExitFault;
  }
  if (!counters_error.empty()) {
    std::printf("FAULT counters_not_saved: %s; rows completed %u, picks %u, beats %u (not on disk)\n",
                counters_error.c_str(), c.rows, c.picks, c.beats);
    return kExitFault;
  }
  if (rows_this_run > 0) {
    // By hand a row is ~5 min knotting + 2 shedding and picking + 3 beating (the thesis, ch. 6). A flat weave
    // has no knots: its rows compare with the 5 min of shed, pick and beat. A knotted row compares whole:
    // the machine's time plus whatever the weaver's hands took (knotting every row, or helping the heads).
    const double per_row = machine_s_rows / rows_this_run;
    if (cfg.knotting.mode == sequencer::KnottingMode::kNone) {
      std::printf("woven %u rows (total %u): %.2f s per row vs ~300 s by hand (shed, pick, beat: %.0fx faster); picks %u, "
                  "beats %u\n",
                  rows_this_run, c.rows, per_row, 300.0 / per_row, c.picks, c.beats);
    } else {
      const double whole = per_row + weaver_outside_s_rows / rows_this_run;
      std::printf("woven %u knotted rows (total %u): %.2f s per whole row (knotting %.2f s by the heads, %.2f s by the "
                  "weaver's hands) vs ~600 s for the weaver's whole row (%.1fx faster); picks %u, beats %u, knots %u tied "
                  "by the heads, %u retried, %u by hand, %u requests to the weaver\n",
                  rows_this_run, c.rows, whole, knot_s_rows / rows_this_run, weaver_s_rows / rows_this_run, 600.0 / whole,
                  c.picks, c.beats, c.knot.tied, c.knot.retried, c.knot.by_hand, weaver_requests);
    }
  }
  return kExitOk;
}

}  // namespace

// CLI11's Range lets NaN through (every comparison with NaN is false): numbers must be finite first.
const CLI::Validator kFinite(
    [](std::string& text) {
      try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used != text.size() || !std::isfinite(v)) return "must be a finite number, not " + text;
      } catch (const std::exception&) {
        return "must be a finite number, not " + text;
      }
      return std::string();
    },
    "FINITE");

int main(int argc, char** argv) {
  CLI::App app{"loomctl — mechanised handmade-carpet loom controller"};
  app.require_subcommand(1);
  WeaveArgs a;
  CLI::App* weave_cmd = app.add_subcommand("weave", "weave rows (simulated loom by default)");
  weave_cmd->add_option("--config", a.config, "loom config file (TOML); default: embedded default loom")
      ->check(CLI::ExistingFile);
  weave_cmd->add_option("--scene", a.scene, "simulation scene file (TOML); default: embedded default scene")
      ->check(CLI::ExistingFile);
  weave_cmd->add_option("--rows", a.rows, "rows to weave")->check(CLI::Range(1u, 1000000u));
  weave_cmd->add_option("--hal", a.hal, "sim | socketcan")->check(CLI::IsMember({"sim", "socketcan"}));
  weave_cmd->add_option("--iface", a.iface, "SocketCAN interface(s) (with --hal socketcan), e.g. can0, or can0,can1 for a loom with axes on two buses");
  weave_cmd->add_option("--io", a.io,
                        "with --hal socketcan: can (the CiA 401 I/O node) | simulated (refused unless given here)")
      ->check(CLI::IsMember({"can", "simulated"}));
  weave_cmd->add_option("--period-ms", a.period_ms, "control period in ms (overrides the config)")
      ->check(kFinite & CLI::Range(0.25, 20.0));
  weave_cmd->add_flag("--realtime", a.realtime, "pace the simulated loom at the tick rate");
  weave_cmd->add_option("--knotting-s", a.knotting_s,
                        "sim, knotting mode: a simulated weaver says \"row knotted\" this many seconds after each "
                        "wait begins")
      ->check(kFinite & CLI::Range(0.0, 3600.0));
  weave_cmd->add_option("--pace", a.pace, "with --realtime: run this many times faster than real time (sim only)")
      ->check(kFinite & CLI::Range(0.01, 1000.0));
  weave_cmd->add_flag("--allow-degraded", a.allow_degraded,
                      "run on hardware even if mlockall/SCHED_FIFO fail (timing not guaranteed)");
  weave_cmd->add_option("--counters", a.counters, "production counters file (resumed, written atomically)");
  weave_cmd->add_option("--lcm-url", a.lcm_url, "LCM provider URL for telemetry (overrides the config)");
  weave_cmd->add_option("--loom-id", a.loom_id, "loom id used in telemetry channel names");
  weave_cmd->add_flag("--no-telemetry", a.no_telemetry, "do not publish LCM telemetry");
  weave_cmd->add_flag("--quiet", a.quiet, "no header");
  weave_cmd->add_option("--report", a.report, "write DIR/summary.json and plots (beat force, row timeline)");
  weave_cmd->add_option("--sim-state", a.sim_state,
                        "sim HAL: keep the simulated machine's physical state in FILE (survives a kill)");
  firmware::CheckArgs check;
  CLI::App* check_cmd = app.add_subcommand("check", "validate a loom config (and scene) and print its plan; moves nothing");
  check_cmd->add_option("--config", check.config, "loom config file (TOML); default: embedded default loom");
  check_cmd->add_option("--scene", check.scene, "simulation scene file (TOML)");
  check_cmd->add_flag("--keys", check.keys, "list every config key with its class (machine/recipe/run) and range");
  firmware::CommissionArgs com;
  CLI::App* com_cmd = app.add_subcommand(
      "commission", "drives disabled: show live axis positions and I/O inputs, capture the calibration into the config");
  com_cmd->add_option("--config", com.config, "the loom config file the calibration is written into")->required();
  com_cmd->add_option("--hal", com.hal, "sim | socketcan")->check(CLI::IsMember({"sim", "socketcan"}));
  com_cmd->add_option("--iface", com.iface, "SocketCAN interface(s) (with --hal socketcan): one per bus, comma-separated");
  com_cmd->add_option("--io", com.io, "can | simulated (overrides io.kind; simulated I/O beside real drives only so)")
      ->check(CLI::IsMember({"can", "simulated"}));
  com_cmd->add_option("--sim-state", com.sim_state, "sim HAL: the simulated machine's physical state file");
  com_cmd->add_option("--capture", com.capture, "capture these at once: park, home, left (non-interactive)")
      ->delimiter(',');
  com_cmd->add_flag("--write", com.write, "with --capture: write the captured values into the config");
  com_cmd->add_flag("--io-once", com.io_once, "print the positions and every input once, then exit");
  com_cmd->add_option("--settle-s", com.settle_s, "non-interactive: run this long before reading")
      ->check(kFinite & CLI::Range(0.05, 30.0));
  const firmware::serve::BoardCommands board(app);  // serve, ctl, --version
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "loomctl: %s\n", e.what());
    return kExitBadInput;
  }
  // An interface without the SocketCAN HAL would silently run the simulated loom: refused.
  for (const auto& [cmd, hal_kind, iface] : {std::tuple{weave_cmd, &a.hal, &a.iface}, std::tuple{com_cmd, &com.hal, &com.iface}}) {
    if (cmd->parsed() && !iface->empty() && *hal_kind != "socketcan") {
      std::fprintf(stderr, "loomctl %s: --iface %s needs --hal socketcan (without it the simulated loom would run)\n",
                   cmd->get_name().c_str(), iface->c_str());
      return kExitBadInput;
    }
  }
  if (check_cmd->parsed()) return firmware::run_check(check);
  if (com_cmd->parsed()) return firmware::run_commission(com);
  if (const auto rc = board.run()) return *rc;
  if (a.hal == "socketcan" && a.iface.empty()) {
    std::fprintf(stderr, "loomctl: --hal socketcan needs --iface NAME\n");
    return kExitBadInput;
  }
  return weave(a);
}
