// How long the knotting heads take to tie a row, from the heads' own sequence rather than a formula: the
// real RowKnotter is stepped against an ideal plant (every servo reads, one tick later, where it was sent;
// every knot is seen tied at its first try), so every term it waits for is counted — the first travel,
// the settle checks, the knot cycles, a carriage step or a selector turn that outlasts the gripper's
// return, and the carriage's way from the last knot to the row's sweep start at the right selvedge (the
// heads knot every row from the left, where the last sweep ended). `loomctl check` prints it.
#pragma once

#include <cstdint>
#include <optional>

#include "loom/hal/types.hpp"
#include "loom/sequencer/sequencer.hpp"

namespace loom::sequencer {

// Configure-time (bounded by `max_ticks`, allocates nothing). The ticks of knotting production row `row0`
// (0-based: its design row follows from it as in the sequencer) with full magazines. nullopt: the loom has no
// heads, or the heads did not finish within `max_ticks` or stopped on a fault (a config the sequencer would
// refuse).
std::optional<hal::Tick> ideal_row_knotting_ticks(const SequencerConfig& cfg, double carriage_travel_m,
                                                  std::uint32_t row0, hal::Tick max_ticks);

}  // namespace loom::sequencer
