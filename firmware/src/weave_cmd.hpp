// `loomctl weave`: one session that weaves rows — on the simulated loom by default (virtual time, as
// fast as the machine allows), in real time with --realtime, or on CAN drives with --hal socketcan —
// and reports them: a line per row, the run's line, a report folder, the knotted carpet's picture.
// Operated with signals: SIGUSR1 pauses at the next safe point, SIGUSR2 resumes, SIGINT/SIGTERM stop at
// the end of the row (a second one at once), SIGHUP reloads the recipe for the next row.
#pragma once

#include <cstdint>
#include <string>

namespace loom::firmware {

struct WeaveArgs {
  std::string config, scene, hal = "sim", iface, counters, lcm_url, loom_id, report, sim_state, io;
  // serve's state directory: counters, the simulated machine, the carpet job queue (the current job is
  // woven, or the next queued one is started: weave runs at the machine)
  std::string state_dir;
  std::uint32_t rows = 3;
  bool rows_given = false;  // --rows on the command line (a job's rows left are the default with a job)
  double period_ms = 0.0;   // 0: the config's
  double pace = 1.0;
  double knotting_s = 0.0;  // sim: a simulated weaver says "row knotted" this long after each wait begins
  bool realtime = false, allow_degraded = false, no_telemetry = false, quiet = false;
};

// Exit code: 0 rows woven, 2 bad input (nothing started), 3 ended in a fault, 4 hardware not armed.
int run_weave(const WeaveArgs& a);

}  // namespace loom::firmware
