// A small state file (counters, the latched fault) written so that a power cut leaves either the old or
// the new version, never a mix — written to PATH.tmp, fsync'd, renamed over PATH, and the folder fsync'd —
// and read back whole without blocking on a FIFO or reading an unbounded file. Non-RT.
#pragma once

#include <cstddef>
#include <string>

namespace loom::firmware {

// Throws std::runtime_error naming the path and the errno text on any failure (the old file stays).
void write_file_durably(const std::string& path, const std::string& body);

// What reading a state file found; each store words its own refusal from it.
struct StateFileRead {
  enum class Outcome {
    kAbsent,      // no such file (the only case a store may start from nothing)
    kCannotOpen,  // it exists but cannot be opened: `error` is the errno text
    kNotRegular,  // not a regular file, or larger than `max_bytes`
    kCannotRead,  // a read failed (`error`: the errno text) or the file shrank ("it shrank")
    kRead,        // `text` is the whole file
  };
  Outcome outcome = Outcome::kAbsent;
  std::string text;
  std::string error;
};
StateFileRead read_state_file(const std::string& path, std::size_t max_bytes);

}  // namespace loom::firmware
