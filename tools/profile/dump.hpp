// `loom-profile dump`: a recipe's profiles written as plain CSV — the scalar facts of the profile set,
// the rocker and crank-law tables as the loop reads them, one row's beat sweep and one pick in time —
// so a committed copy (tests/motion/profiles/golden/) catches any unintended change in motion.
#pragma once

#include <string>

#include "loom/motion/profile_set.hpp"

namespace loom::profile {

// Configure-time only. Writes DIR/{profile_set,rocker,crank_law,beat_sweep,pick}.csv (DIR must
// exist). `period_s` is the tick the sweep and pick are sampled at. Throws std::runtime_error naming
// the file that cannot be written.
void write_dump(const motion::ProfileSet& set, double period_s, const std::string& dir);

}  // namespace loom::profile
