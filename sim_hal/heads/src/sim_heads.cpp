// The knotting heads as the simulators see them (see sim_heads.hpp).
#include "loom/sim_heads/sim_heads.hpp"

#include <stdexcept>

#include "loom/motion/errors.hpp"
#include "loom/sequencer/row_knotter.hpp"

namespace loom::firmware {

sim_hal::SimKnotting sim_knotting(const sequencer::SequencerConfig& s) {
  const sequencer::KnotProgram& p = *s.heads.program;
  // Where the gripper is in the warp: the interlocks' own derivation from the knot cycle, so the
  // simulated heads and the guard agree on the linkage (the guard is checked against this plant).
  const sequencer::KnotGuard g = sequencer::knot_guard(s.heads);
  sim_hal::SimKnotting k;
  k.heads = p.heads();
  k.knots_per_row = p.knots_per_row();
  k.stripe = p.stripe();
  k.slots = p.slots();
  k.knots_per_slot = p.knots_per_slot();
  k.pitch_m = p.pitch_m();
  k.carriage_home_m = s.carriage_home_m;
  for (int h = 0; h < k.heads; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    k.knotter_axis[hh] = static_cast<std::size_t>(s.heads.knotter_axis[hh]);
    k.selector_axis[hh] = static_cast<std::size_t>(s.heads.selector_axis[hh]);
  }
  k.take_position_rad = g.take_position_rad;
  k.selector_zero_rad = s.heads.selector_zero_rad;
  k.in_warp_from_rad = g.in_warp_from_rad;
  k.in_warp_to_rad = g.in_warp_to_rad;
  k.full_turn = g.full_turn;
  // The carpet's length, so the simulator's record of it is sized here, before the tick: the run's last row
  // (the sequencer stops after it) or, with no end, a pass of the design.
  k.last_row = s.rows_to_weave;
  k.design_rows = p.design_rows();
  return k;
}

KnottingHeads build_heads(const LoomConfig& c, std::uint64_t design_rows_done, std::uint32_t counter_rows) {
  if (c.knotting.mode != sequencer::KnottingMode::kHeads) {
    throw ConfigError(c.source + ": knotting.mode = \"" + sequencer::knotting_mode_name(c.knotting.mode) +
                      "\": the loom has no knotting heads");
  }
  if (!c.recipe.design) {
    throw ConfigError(!c.recipe.design_missing.empty()
                          ? c.recipe.design_missing
                          : c.source +
                                ": knotting.mode = \"heads\": the heads tie the design's knots; set "
                                "recipe.design");
  }
  KnottingHeads out;
  try {
    out.cycle = std::make_unique<const motion::KnotCycle>(motion::KnotCycle::build(c.knot_cycle));
  } catch (const motion::MotionError& e) {
    throw ConfigError(c.source + ": [knotting.linkage]: " + e.what());
  }
  try {
    out.program =
        std::make_unique<const sequencer::KnotProgram>(knot_program(c, design_rows_done, counter_rows));
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.source + ": recipe.design = \"" + c.recipe.design_file + "\": " + e.what());
  }
  return out;
}

SimHeads sim_heads(const LoomConfig& c) {
  SimHeads out{build_heads(c, 0, 0), {}};
  sequencer::SequencerConfig s = c.sequencer;
  s.heads.program = out.heads.program.get();
  s.heads.cycle = out.heads.cycle.get();
  out.knotting = sim_knotting(s);
  return out;
}

}  // namespace loom::firmware
