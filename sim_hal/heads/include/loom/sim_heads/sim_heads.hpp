// The knotting heads as the simulators see them: the in-process SimWorld (scene effect "knotter") and
// loom-sim-drive's I/O node behind a real CAN master. Both are told the same facts the sequencer knots
// with — derived here once, never copied into a simulator's own options.
#pragma once

#include <memory>

#include "loom/config/config.hpp"
#include "loom/motion/knot_cycle.hpp"
#include "loom/sequencer/knot_program.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/knotter.hpp"

namespace loom::firmware {

// Configure-time. `s.heads` must carry its program and cycle.
sim_hal::SimKnotting sim_knotting(const sequencer::SequencerConfig& s);

// Configure-time. A loom's heads (knotting.mode = "heads"): the knot cycle through its linkage and the design
// as knots, the design's progress saying which row comes next (see knot_program()). Throws ConfigError
// naming the config (a loom without heads or design, a linkage or design that does not build).
struct KnottingHeads {
  std::unique_ptr<const motion::KnotCycle> cycle;
  std::unique_ptr<const sequencer::KnotProgram> program;
};
KnottingHeads build_heads(const LoomConfig& c, std::uint64_t design_rows_done, std::uint32_t counter_rows);

// Configure-time. What a simulator without a Machine (loom-sim-drive) needs to model a loom's heads.
struct SimHeads {
  KnottingHeads heads;
  sim_hal::SimKnotting knotting;
};
SimHeads sim_heads(const LoomConfig& c);

}  // namespace loom::firmware
