// `loom-kin needle`: the tufting-needle six-bar of seed 002 over one main-shaft turn as CSV
// (theta1_deg..theta5_deg, needle_mm), from Table 1 unless options change a parameter.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace loom::kin {

struct NeedleArgs {
  int samples = 3600;
  // Table 1 of 002, mm and degrees as printed there.
  double l1_mm = 15, l2_mm = 138, l3_mm = 115, l4_mm = 125, l5_mm = 120, l6_mm = 440;
  double x1_mm = 70, x2_mm = 100, h1_mm = 155, beta1_deg = 168;
  std::string rocker_side = "away";  // 002: B away from the needle side of O-C
  std::string rod_side = "hanging";  // 002: the rod hangs from D down to the needle bar
  double rpm = 160;                  // 002's experiment; only matters with --rates
  bool rates = false;
};

// Configure-time only. Registers the subcommand and its options on `app`.
CLI::App* add_needle_command(CLI::App& app, NeedleArgs& args);
// Configure-time only. Writes the CSV to stdout; throws loom::motion::MotionError on an impossible
// design (the caller reports it and exits 2).
void run_needle(const NeedleArgs& args);

}  // namespace loom::kin
