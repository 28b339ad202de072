// The persistent fault history a technician reads back (`loomctl ctl faults`): an append-only text
// file in the state directory, one line per fault or acknowledgement, each written and fsync-ed before
// the call returns. Bounded: when the file would exceed `max_bytes` it is rotated to `<file>.1` (one
// generation kept), so the history holds between max_bytes and 2·max_bytes of the newest lines.
// Non-RT; thread-safe (the reporter appends while the control thread reads).
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace loom::firmware::serve {

struct FaultRecord {
  std::string loom_id;
  std::string kind = "fault";  // "fault" | "ack" | "overrun_stop"
  std::string name;            // fault name from the one fault table, e.g. "drive_fault"
  std::uint16_t code = 0;
  std::string axis;  // "" when not axis-specific
  std::uint16_t device_code = 0;
  std::uint32_t rows = 0, picks = 0, beats = 0;
  std::string text;  // operator text
};

class FaultHistory {
 public:
  // Configure-time. `path` is the file (e.g. /var/lib/loomctl/faults.log); its folder must exist.
  explicit FaultHistory(std::string path, std::uint64_t max_bytes = 256u << 10);

  // Appends one line "2026-11-23T20:15:03Z fault loom1 drive_fault 0x1002 axis=carriage device=0x7310
  // rows=3 picks=3 beats=45: a servo drive reported a fault". Throws std::runtime_error naming the
  // file when it cannot be written.
  void append(const FaultRecord& r);
  // Oldest first: the rotated generation, then the current file.
  std::vector<std::string> read_all() const;
  const std::string& path() const { return path_; }

  static std::string format(const FaultRecord& r, std::int64_t unix_s);

 private:
  std::string path_;
  std::uint64_t max_bytes_;
  mutable std::mutex mu_;
};

}  // namespace loom::firmware::serve
