// `loom-kin fourbar`: any four-bar over one crank turn as CSV (angles, kinematic coefficients,
// transmission angle, optionally a point on a link with its velocity and acceleration), or with
// --summary one row of Grashof class, transmission extremes and dead centres.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace loom::kin {

struct FourBarArgs {
  double ground = 1.0;  // lengths relative to ground = 1 unless a ground length is given
  double crank = 0.0, coupler = 0.0, rocker = 0.0;
  std::string branch = "positive";
  int samples = 360;
  double start_deg = 0.0;
  bool summary = false;
  std::string point_link;  // crank | coupler | rocker; empty: no point columns
  double point_x = 0.0, point_y = 0.0;
  double omega = 1.0, alpha = 0.0;  // crank rate and acceleration for the point columns
};

// Configure-time only. Registers the subcommand and its options on `app`.
CLI::App* add_fourbar_command(CLI::App& app, FourBarArgs& args);
// Configure-time only. Writes the CSV to stdout; throws loom::motion::MotionError (its message
// naming the options involved) when the linkage cannot do what was asked.
void run_fourbar(const FourBarArgs& args);

}  // namespace loom::kin
