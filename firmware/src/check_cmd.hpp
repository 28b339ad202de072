// `loomctl check --config FILE [--scene FILE]`: validate a machine description and print the plan it
// derives (crank speed and why, beats, windows, carriage steps, pick, row time, CAN load), moving
// nothing. `--keys` lists every config key with its class and plausible range.
#pragma once

#include <string>

namespace loom::firmware {

struct CheckArgs {
  std::string config, scene;
  bool keys = false;
};

// Exit code: 0 valid, 2 bad input (the error on stderr names file:line:col, key and value).
int run_check(const CheckArgs& a);

}  // namespace loom::firmware
