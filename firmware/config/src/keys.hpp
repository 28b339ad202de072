// The key table of a loom file: every key with its class (machine, recipe, run), its plausible range,
// its reader and its canonical value. Internal to loom::config; config_keys() is the public view.
#pragma once

#include <functional>
#include <set>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"

namespace loom::firmware::detail {

enum class Klass { kMachine, kRecipe, kRun };
const char* klass_name(Klass k);

struct Key {
  std::string path;
  Klass klass;
  std::string range;  // for messages and `loomctl check --keys`
  bool required;      // must be in a complete file (false: has a documented default or an alternative)
  std::function<void(TomlReader&, LoomConfig&)> read;
  std::function<std::string(const LoomConfig&)> value;  // canonical text, to compare two configs
};

// Every key in file order.
const std::vector<Key>& keys();
// The key at `path`, or null.
const Key* find_key(const std::string& path);
// The canonical value of the key at `path` in `c` ("" if there is no such key).
std::string value_of(const LoomConfig& c, const std::string& path);
// The top-level tables a loom file may have.
const std::set<std::string>& known_sections();

// Keys of the three-axis layout that became [axes.<name>] tables: a file that still says them is refused
// with the line and where the fact lives now (a typo-proof migration: nothing is silently ignored).
void refuse_moved_keys(TomlReader& r);

// A number as messages show it (10 significant digits).
std::string fmt_num(double v);

// Where a derived problem is reported: the key in the file that the user can change to fix it.
using Fail = std::function<void(const std::string& key, const std::string& value, const std::string& why)>;

}  // namespace loom::firmware::detail
