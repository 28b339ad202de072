// Production counters on disk, so a power cut never loses or repeats a row: written atomically
// (temp file, fsync, rename, fsync of the directory). Non-RT: called from the reporter, never the tick.
//
// Counters are never silently reset, wrapped or guessed: a file that exists but cannot be read, is
// not a counters file, holds a value that is not a whole number in 0..4294967295, or whose counts
// contradict each other is refused (ConfigError naming the file, field and value; the file is left
// untouched). Only a file that does not exist starts from zero.
#pragma once

#include <optional>
#include <string>

#include "loom/sequencer/sequencer.hpp"

namespace loom::state {

class CounterStore {
 public:
  explicit CounterStore(std::string path) : path_(std::move(path)) {}
  // Missing file → nullopt. Anything else that is not a valid counters file → ConfigError.
  std::optional<sequencer::Counters> load() const;
  // Throws std::runtime_error naming the path and errno text on failure (nothing half-written: the
  // previous file stays in place).
  void save(const sequencer::Counters& c) const;
  const std::string& path() const { return path_; }

  // The counters' text and its strict parser (exposed for tests and fuzzing). `source` names the
  // file in errors.
  static std::string format(const sequencer::Counters& c);
  static sequencer::Counters parse(const std::string& text, const std::string& source);

 private:
  std::string path_;
};

}  // namespace loom::state
