// The beat-up linkage of a loom config (the [beatup] section of the machine description loomctl reads,
// keys named exactly as there) for the offline design tools: link lengths, branch, fell side, warp
// depth, beater mass, and the crank speed or beat-force target when given. Other sections and keys the
// design tools do not need are left to loomctl's own validation. Offline-tool code (configure-time).
#pragma once

#include <optional>
#include <string>

#include "loom/motion/beatup.hpp"

namespace loom::cli {

struct BeatupConfig {
  motion::BeatUpGeometry geometry;
  double beater_mass_kg = 2.5;
  std::optional<double> crank_speed_rad_s;
  std::optional<double> beat_force_target_n;
};

// Reads `path`. Throws UsageError (run.hpp) naming file:line:col, the key and its value for an
// unreadable file, a TOML syntax error, a missing [beatup] section or key, or a bad value.
BeatupConfig read_beatup_config(const std::string& path);

}  // namespace loom::cli
