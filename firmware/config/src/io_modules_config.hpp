// [io_modules.<name>] tables: the CiA 401 modules a loom has beside the [io] table's own, and which
// signals each carries. Part of reading a loom file (config.cpp); kept apart because it is one job.
#pragma once

#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"

namespace loom::firmware {

// Reads every [io_modules.<name>] table over what `c` already holds (an extended file keeps the base's
// modules and may change them), then puts each listed signal on its module (IoBit::module, the heads'
// HeadSignals::module, the load cell's module); every other signal is on the [io] module. Refusals name
// file:line, key and value: an unknown signal (with the known ones), a signal two modules list, more
// modules than the controller holds, a module with no signals.
void read_io_modules(TomlReader& r, LoomConfig& c);

// The names a module's `signals` list may hold, in [io] key order.
const std::vector<std::string>& io_signal_names();

// The canonical text of the modules, to tell a restart-only change.
std::string io_modules_text(const LoomConfig& c);

// The keys of one [io_modules.<name>] table with their ranges (the README's key table).
struct IoModuleKeyInfo {
  const char* path;
  const char* range;
};
const std::vector<IoModuleKeyInfo>& io_module_keys();

}  // namespace loom::firmware
