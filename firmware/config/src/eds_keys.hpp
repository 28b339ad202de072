// The `eds` keys of a loom file (axes.<name>.eds, io.eds, io_modules.<name>.eds): reading the path and
// refusing a description that cannot be read, or a key the description contradicts. Internal to
// loom::config.
#pragma once

#include <string>

#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"

namespace loom::firmware::detail {

// Reads the string at `path` (when present) into `out`: a relative path is taken relative to the folder
// of the file being read, so a machine description and its vendors' files move together.
void read_eds_key(TomlReader& r, const std::string& path, std::string& out);
// Reads io.input_group_bits / io_modules.<name>.input_group_bits (when present): 8 or 16, else refused.
void read_input_group_bits(TomlReader& r, const std::string& path, int& out);

// Every named EDS is read (non-strict); a file with errors is refused at its key, quoting the EDS's
// file:line; a key that contradicts the description is refused at that key's line, quoting the EDS's
// file:line (a homing axis whose drive lists no homing mode, a heartbeat outside 0x1017's limits, a
// drive's file given for an I/O module or the other way round, a load cell channel the module lacks,
// input groups the module lacks); store_config = true needs an EDS with a writable 0x1010:01.
void check_eds_keys(const TomlReader& r, const LoomConfig& c);

}  // namespace loom::firmware::detail
