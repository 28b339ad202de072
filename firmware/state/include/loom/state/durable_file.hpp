// A small state file (counters, the latched fault) written so that a power cut leaves either the old or
// the new version, never a mix — written to PATH.tmp, fsync'd, renamed over PATH, and the folder fsync'd —
// and read back whole without blocking on a FIFO or reading an unbounded file. Non-RT.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace loom::state {

// A failed durable write: the message names the path and the errno text; `error` is the errno.
struct DurableWriteError : std::runtime_error {
  DurableWriteError(const std::string& what, int err) : std::runtime_error(what), error(err) {}
  int error;
};

// Throws DurableWriteError on any failure (the old file stays).
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

// Room kept in reserve beside the state files: a record that must be written whatever the disk holds — the
// fault that latched because the counters could not be saved on a full disk — frees it first and then
// fits. The service makes it when it arms (a disk too full to hold it refuses to arm, as a counters file
// that cannot be written does) and releases it only to write such a record. Non-RT.
class DiskReserve {
 public:
  explicit DiskReserve(std::string path, std::size_t bytes = 64u << 10)
      : path_(std::move(path)), bytes_(bytes) {}
  // Makes the reserve (written, fsync'd, not sparse) unless it is there whole. Throws std::runtime_error
  // naming the path when the disk cannot hold it (nothing left behind).
  void ensure() const;
  // Deletes it (and syncs the folder) so that a record that must be written fits; false when there was none.
  bool release() const noexcept;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::size_t bytes_;
};

// write_file_durably(), and when the disk is full (or out of quota) `reserve` released and the write tried
// once more: for the records that must not be lost to a full disk.
void write_file_durably(const std::string& path, const std::string& body, const DiskReserve& reserve);

}  // namespace loom::state
