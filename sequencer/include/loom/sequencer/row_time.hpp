// How long the knotting heads take to tie a row, from the heads' own sequence rather than a formula: the
// real RowKnotter is stepped against an ideal plant (every servo reads, one tick later, where it was sent;
// every knot is seen tied at its first try), so every term it waits for is counted — the first travel,
// the settle checks, the knot cycles, a carriage step or a selector turn that outlasts the gripper's
// return, and the carriage's way back to the row's start selvedge (a row that starts at the right
// selvedge crosses to the left one first: the heads knot from the left). `loomctl check` prints it.
#pragma once

#include <cstdint>
#include <optional>

#include "loom/hal/types.hpp"
#include "loom/sequencer/sequencer.hpp"

namespace loom::sequencer {

// Configure-time (bounded by `max_ticks`, allocates nothing). The ticks of knotting production row `row0`
// (0-based: its design row and its start selvedge follow from it as in the sequencer, even rows from the
// left) with full magazines. nullopt: the loom has no heads, or the heads did not finish within
// `max_ticks` or stopped on a fault (a config the sequencer would refuse).
std::optional<hal::Tick> ideal_row_knotting_ticks(const SequencerConfig& cfg, double carriage_travel_m,
                                                  std::uint32_t row0, hal::Tick max_ticks);

}  // namespace loom::sequencer
