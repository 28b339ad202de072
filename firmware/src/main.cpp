// loomctl — the loom controller's command line: which command runs, with which arguments. Each command
// is its own module (weave_cmd, check_cmd, commission_cmd, serve/); the steps they share — build the
// machine, arm it, run the loop, report — are firmware::Session's.
// Exit codes: 0 done, 2 bad input (nothing started), 3 ended in a fault, 4 hardware not armed.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "check_cmd.hpp"
#include "commission_cmd.hpp"
#include "dcf_cmd.hpp"
#include "design_cmd.hpp"
#include "job_cmd.hpp"
#include "loom/firmware/serve/commands.hpp"
#include "loom/firmware/session.hpp"
#include "report_cmd.hpp"
#include "weave_cmd.hpp"

using namespace loom;
using firmware::kExitBadInput;

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
  firmware::WeaveArgs a;
  CLI::App* weave_cmd = app.add_subcommand("weave", "weave rows (simulated loom by default)");
  weave_cmd->add_option("--config", a.config, "loom config file (TOML); default: embedded default loom")
      ->check(CLI::ExistingFile);
  weave_cmd->add_option("--scene", a.scene, "simulation scene file (TOML); default: embedded default scene")
      ->check(CLI::ExistingFile);
  CLI::Option* weave_rows =
      weave_cmd
          ->add_option("--rows", a.rows,
                       "rows to weave (with a carpet job: at most its rows left, the default)")
          ->check(CLI::Range(1u, 1000000u));
  weave_cmd->add_option("--hal", a.hal, "sim | socketcan")->check(CLI::IsMember({"sim", "socketcan"}));
  weave_cmd->add_option("--iface", a.iface,
                        "SocketCAN interface(s) (with --hal socketcan), e.g. can0, or can0,can1 for a loom "
                        "with axes on two buses");
  weave_cmd
      ->add_option("--io", a.io,
                   "with --hal socketcan: can (the CiA 401 I/O node) | simulated (refused unless given here)")
      ->check(CLI::IsMember({"can", "simulated"}));
  weave_cmd->add_option("--period-ms", a.period_ms, "control period in ms (overrides the config)")
      ->check(kFinite & CLI::Range(0.25, 20.0));
  weave_cmd->add_flag("--realtime", a.realtime, "pace the simulated loom at the tick rate");
  weave_cmd
      ->add_option("--knotting-s", a.knotting_s,
                   "sim, knotting mode: a simulated weaver says \"row knotted\" this many seconds after each "
                   "wait begins")
      ->check(kFinite & CLI::Range(0.0, 3600.0));
  weave_cmd
      ->add_option("--pace", a.pace, "with --realtime: run this many times faster than real time (sim only)")
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
  weave_cmd
      ->add_option(
          "--state-dir", a.state_dir,
          "serve's state directory: its counters, simulated machine and carpet job queue (weaves the "
          "current job, or starts the next queued one)")
      ->excludes("--counters")
      ->excludes("--sim-state");
  firmware::CheckArgs check;
  CLI::App* check_cmd =
      app.add_subcommand("check", "validate a loom config (and scene) and print its plan; moves nothing");
  check_cmd->add_option("--config", check.config, "loom config file (TOML); default: embedded default loom");
  check_cmd->add_option("--scene", check.scene, "simulation scene file (TOML)");
  check_cmd->add_flag("--keys", check.keys,
                      "list every config key with its class (machine/recipe/run) and range");
  firmware::CommissionArgs com;
  firmware::DcfArgs dcf;
  CLI::App* dcf_cmd = app.add_subcommand("dcf",
                                         "write a DCF (CiA 306) per node that names its EDS, with the values "
                                         "the loom configures; moves nothing");
  dcf_cmd->add_option("--config", dcf.config, "loom config file (TOML); default: embedded default loom");
  dcf_cmd->add_option("--out", dcf.out, "folder for the DCF files (created if missing)")->required();
  CLI::App* com_cmd = app.add_subcommand(
      "commission",
      "drives disabled: show live axis positions and I/O inputs, capture the calibration into the config");
  com_cmd->add_option("--config", com.config, "the loom config file the calibration is written into")
      ->required();
  com_cmd->add_option("--hal", com.hal, "sim | socketcan")->check(CLI::IsMember({"sim", "socketcan"}));
  com_cmd->add_option("--iface", com.iface,
                      "SocketCAN interface(s) (with --hal socketcan): one per bus, comma-separated");
  com_cmd
      ->add_option("--io", com.io,
                   "can | simulated (overrides io.kind; simulated I/O beside real drives only so)")
      ->check(CLI::IsMember({"can", "simulated"}));
  com_cmd->add_option("--sim-state", com.sim_state, "sim HAL: the simulated machine's physical state file");
  com_cmd->add_option("--capture", com.capture, "capture these at once: park, home, left (non-interactive)")
      ->delimiter(',');
  com_cmd->add_flag("--write", com.write, "with --capture: write the captured values into the config");
  com_cmd->add_flag("--io-once", com.io_once, "print the positions and every input once, then exit");
  com_cmd->add_option("--settle-s", com.settle_s, "non-interactive: run this long before reading")
      ->check(kFinite & CLI::Range(0.05, 30.0));
  const firmware::serve::BoardCommands board(app);  // serve, ctl, --version
  const firmware::DesignCommand design(app);        // design fit
  const firmware::JobCommands jobs(app);
  const firmware::ReportCommands reports(app);
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
  if (check_cmd->parsed()) return firmware::run_check(check);
  if (com_cmd->parsed()) return firmware::run_commission(com);
  if (dcf_cmd->parsed()) return firmware::run_dcf(dcf);
  if (const auto rc = board.run()) return *rc;
  if (const auto rc = design.run()) return *rc;
  if (const auto rc = jobs.run()) return *rc;
  if (const auto rc = reports.run()) return *rc;
  a.rows_given = weave_rows->count() > 0;
  return firmware::run_weave(a);
}
