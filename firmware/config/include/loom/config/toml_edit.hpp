// Rewrites chosen `key = value` lines of a TOML file in place, leaving every other byte as it was, so a
// config keeps its comments, its layout and the line numbers people and error messages refer to.
// For `loomctl commission`, which writes measured calibration values into the loom's own file.
#pragma once

#include <string>
#include <vector>

namespace loom::firmware {

struct TomlAssignment {
  std::string section;  // e.g. "beatup" (top-level tables only: that is all a loom config has)
  std::string key;      // e.g. "crank_park_position_rad"
  std::string value;    // TOML text of the new value, e.g. "0.123456789"
};

// Configure-time only. Replaces the value of each assignment's line in its section (the trailing
// comment kept); a key the file does not have is added as the section's first line, and a section it
// does not have is appended at the end. `changes` gets one line per assignment, "N: section.key =
// value (was OLD)" or "(added)". Throws ConfigError when a key sits on a line it cannot rewrite safely
// (a multi-line value, an inline table).
std::string set_toml_values(const std::string& text, const std::vector<TomlAssignment>& assignments,
                            std::vector<std::string>& changes);

}  // namespace loom::firmware
