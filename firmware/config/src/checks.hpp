// The cross-field checks of a loom file and each module's own validation at parse time, each refusal
// pinned to the key the user can change. Internal to loom::config.
#pragma once

#include "keys.hpp"
#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"

namespace loom::firmware::detail {

// Relations between the file's facts (before derivation): node ids, the linkage's class, widths and
// bands, the knotting spec and linkage, the shed's windows; at the line that is wrong.
void check_relations(const TomlReader& r, const LoomConfig& c);
// The CAN master's own validation (drives and I/O modules) and each bus' worst-case load.
void check_can(const LoomConfig& c, const Fail& fail);
// The derived motion must be buildable, fit the sequencer's fixed capacities and end in finite time.
void check_motion(const LoomConfig& c, const Fail& fail);
// The loop period must resolve the beat.
void check_beat_resolution(const LoomConfig& c, const Fail& fail);

}  // namespace loom::firmware::detail
