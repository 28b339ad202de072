// `loom-kin slider-crank`: an offset slider-crank over one crank turn as CSV (slider position,
// velocity and acceleration, coupler angle and its rates, transmission angle), or with --summary one
// row of dead centres, stroke, crank rotations, time ratio and minimum transmission angle.
#pragma once

#include <CLI/CLI.hpp>

namespace loom::kin {

struct SliderCrankArgs {
  double crank = 0.0, coupler = 0.0, offset = 0.0;  // any one length unit
  int samples = 360;
  double omega = 1.0, alpha = 0.0;  // crank rate (rad/s) and acceleration (rad/s²)
  bool summary = false;
};

// Configure-time only. Registers the subcommand and its options on `app`.
CLI::App* add_slider_crank_command(CLI::App& app, SliderCrankArgs& args);
// Configure-time only. Writes the CSV to stdout; throws loom::motion::MotionError (its message
// naming the options involved) when the linkage cannot turn.
void run_slider_crank(const SliderCrankArgs& args);

}  // namespace loom::kin
