// The one derivation of every module's config from a loom file's facts. Internal to loom::config;
// derive_module_configs() is the public entry.
#pragma once

#include "keys.hpp"
#include "loom/config/config.hpp"

namespace loom::firmware::detail {

// Fills c.profile, c.sequencer and c.machine from the machine, recipe and run settings; a recipe that
// cannot be met (a force target the linkage cannot give) goes to `fail` at its key.
void derive(LoomConfig& c, const Fail& fail);

// Crank speed at the fell / master speed: 1 at constant speed, the crank law's ratio where the crank
// reaches the fell otherwise.
double beat_speed_ratio(const LoomConfig& c);

}  // namespace loom::firmware::detail
