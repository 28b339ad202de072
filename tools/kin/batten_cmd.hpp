// `loom-kin batten` (one driving-pinion turn of the elliptic-gear batten drive of seed 004 as CSV)
// and `loom-kin batten-phase` (scan of the crank phase φ02: batten acceleration at its turning
// points and over the turn, and the gain over a circular gear — the optimisation 004 describes).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace loom::kin {

struct BattenArgs {
  int samples = 3600;
  double e = 0.2;  // 004 compares e = 0 and e = 0.2
  double phi02_rad = 0.0;
  double a_m = 0.05;
  int k = 2;
  double omega1_rad_s = 1.0;  // 004: ω1 = 1 rad/s
  // 004's link lengths and ground offsets, m.
  double l_m[9] = {0.04, 0.09, 0.08, 0.09, 0.17, 0.1, 0.06, 0.05, 0.11};
  std::string loop1 = "right";
  std::string loop2 = "right";
  std::string solver = "closed";
  double newton_tol = 1e-13;
  bool pose = false;
  double step_deg = 1.0;  // batten-phase only
};

// Configure-time only. Register the subcommands and their options on `app`.
CLI::App* add_batten_command(CLI::App& app, BattenArgs& args);
CLI::App* add_batten_phase_command(CLI::App& app, BattenArgs& args);
// Configure-time only. Write the CSV to stdout (warnings about a near-degenerate or uncuttable gear
// to stderr); throw loom::motion::MotionError on an impossible design.
void run_batten(const BattenArgs& args);
void run_batten_phase(const BattenArgs& args);

}  // namespace loom::kin
