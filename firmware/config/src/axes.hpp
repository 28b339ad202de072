// The axes of a loom file: [axes.<name>] tables, one per servo axis. Internal to loom::config.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"

namespace loom::firmware::detail {

constexpr std::int64_t kMaxBuses = 4;  // CAN interfaces one controller drives

// The keys of one [axes.<name>] table with their ranges (the README's key table).
struct AxisKeyInfo {
  const char* path;
  const char* range;
};
const std::vector<AxisKeyInfo>& axis_keys();

// The canonical text of the axes, to tell a restart-only change.
std::string axes_text(const LoomConfig& c);

// Reads every [axes.<name>] table over what `c` already holds (the embedded default's axes when the
// file extends it), then puts the axes in slot order and checks the set: each core role exactly once,
// at most hal::kMaxAxes axes.
void read_axes(TomlReader& r, LoomConfig& c, bool extending);

}  // namespace loom::firmware::detail
