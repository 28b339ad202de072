// A thin reader over toml++ that turns every problem into one ConfigError line
// "file:line:col: field = value: why", and rejects keys nobody asked for (typos must not pass).
#pragma once

#include <toml++/toml.h>

#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "loom/config/config.hpp"

namespace loom::firmware {

class TomlReader {
 public:
  TomlReader(const std::string& text, std::string source);

  const std::string& source() const { return source_; }
  const toml::table& root() const { return root_; }

  // Read `table.key` into `out` if present; `check` returns "" when valid or the reason.
  void number(const std::string& path, double& out, const std::function<std::string(double)>& check = {});
  void integer(const std::string& path, std::int64_t& out, std::int64_t lo, std::int64_t hi);
  void boolean(const std::string& path, bool& out);
  void string(const std::string& path, std::string& out, const std::set<std::string>& allowed = {});
  void string_list(const std::string& path, std::vector<std::string>& out);
  // Every entry an integer in lo..hi; at most max_size of them.
  void integer_list(const std::string& path, std::vector<int>& out, int lo, int hi, std::size_t max_size);

  // "file:line:col: path = value: why" at the node for `path` (or the file start when absent): what fail()
  // throws, for a refusal said later (e.g. when the loom arms).
  std::string message(const std::string& path, const std::string& value, const std::string& why) const;
  // Error at the node for `path` (or the file start when absent).
  [[noreturn]] void fail(const std::string& path, const std::string& value, const std::string& why) const;
  [[noreturn]] void fail_at(const toml::node& node, const std::string& field, const std::string& value,
                            const std::string& why) const;
  // A required key the file does not have: reported at its section's header (or the file's start).
  [[noreturn]] void fail_missing(const std::string& path, const std::string& why) const;

  // After reading: every key in the file must have been consumed (arrays of tables are checked by
  // their readers through `consume`).
  void consume(const std::string& path) { used_.insert(path); }
  void reject_unknown() const;
  // As reject_unknown, and a top-level table outside `sections` is reported as an unknown *section*
  // (with the closest known name), not as its first key.
  void reject_unknown(const std::set<std::string>& sections) const;

 private:
  const toml::node* find(const std::string& path) const;
  std::string show(const toml::node& n) const;  // the value as written, for messages
  std::vector<std::string> lines_;
  std::string source_;
  toml::table root_;
  std::set<std::string> used_;
};

// Configure-time only. The text of a config, scene or design file: a regular file of at most
// `max_bytes` (a FIFO, a device or /dev/zero is refused instead of blocking or reading without bound).
// `what` names the kind of file in the size refusal.
std::string read_config_file(const std::string& path, long max_bytes = 1L << 20, const char* what = "config");

// Common checks.
std::string positive(double v);
std::string non_negative(double v);
std::string in_range(double v, double lo, double hi);  // "" or "must be in [lo, hi]"

}  // namespace loom::firmware
