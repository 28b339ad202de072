// Production counters on disk, so a power cut never loses or repeats a row: written atomically
// (temp file, fsync, rename, fsync of the directory). Non-RT: called from the reporter, never the tick.
#pragma once

#include <optional>
#include <string>

#include "loom/sequencer/sequencer.hpp"

namespace loom::firmware {

class CounterStore {
 public:
  explicit CounterStore(std::string path) : path_(std::move(path)) {}
  // Missing file → nullopt; a malformed file is a ConfigError naming it (never silently zeroed).
  std::optional<sequencer::Counters> load() const;
  // Throws std::runtime_error naming the path and errno text on failure.
  void save(const sequencer::Counters& c) const;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace loom::firmware
