// `loomctl commission --config FILE`: bring the bus up with every drive left DISABLED (the sequencer
// stays idle: no enable, no motion, valves holding), show the axes' actual positions and the I/O node's
// inputs live, and write the calibration the loom builder captures — the crank at its park pose, the
// carriage at the left selvedge, the helix carrier at the left selvedge — into the config file itself
// (every other line untouched). Interactive on a terminal (type park, home, left, write, quit); or
// non-interactive: --capture park,home,left [--write] and --io-once for scripts and tests.
#pragma once

#include <string>
#include <vector>

namespace loom::firmware {

struct CommissionArgs {
  std::string config;  // required: the file the calibration is written into
  std::string hal = "sim", iface, io, sim_state;
  std::vector<std::string> capture;  // park, home, left: capture these at once (non-interactive)
  bool write = false;                // with --capture: write them into the config
  bool io_once = false;              // print positions and every input once, then exit
  double settle_s = 0.5;             // non-interactive: run this long before reading (first PDOs, debounce)
};

// Exit code: 0 done, 2 bad input, 4 cannot bring the bus up.
int run_commission(const CommissionArgs& a);

}  // namespace loom::firmware
