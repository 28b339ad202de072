// The carpet the simulated loom actually knotted, as a picture beside the run report: one pixel per knot
// in the design's own orientation (the last row woven at the top), each knot in its yarn's colour. The
// alpha channel marks how it was tied: 255 by a head, 128 by the weaver's hand, 0 not at all. Compared
// with the design knot for knot on the way. After the run only (allocates, writes a file).
#pragma once

#include <string>

#include "loom/design/design.hpp"
#include "loom/sequencer/knot_program.hpp"
#include "loom/sim_hal/knotter.hpp"

namespace loom::report {

struct CarpetCheck {
  int rows = 0;   // rows compared: every row knotted and every row woven, whichever is more
  int knots = 0;  // knots tied (by heads and by hand)
  int by_hand = 0;
  int missing = 0;     // knots of those rows not tied
  int doubled = 0;     // knot positions tied more than once
  int wrong = 0;       // knots whose colour is not the design's
  int unrecorded = 0;  // knots tied beyond the simulator's record (its carpet_rows too short): not compared
  bool equal() const { return missing == 0 && doubled == 0 && wrong == 0 && unrecorded == 0; }
};

// Compares the knotted rows with `program`'s design rows from production row `first_row` (0-based) and
// writes `path` (PNG). `rows_woven`: the rows the counters say were woven since `first_row`; a row woven
// but not (or not wholly) in the carpet counts its knots as missing. Throws std::runtime_error when the
// file cannot be written.
CarpetCheck write_carpet_png(const sim_hal::SimKnotter& carpet, const sequencer::KnotProgram& program,
                             const design::Design& design, std::uint32_t first_row, const std::string& path,
                             int rows_woven = 0);

}  // namespace loom::report
