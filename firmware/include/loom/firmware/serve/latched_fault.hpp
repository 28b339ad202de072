// The fault latched in `loomctl serve`, kept on disk beside the counters until it is acknowledged: a
// restart (service stop, power cut, watchdog) is not the deliberate reset IEC 60204-1 asks for, so a
// fault latched when serve stopped is latched again when it arms, `ctl status` shows it, starting
// commands are refused, and only `ctl ack` or the ack button clears it (and this file).
//
// The file (STATE/latched-fault) is written with state::write_file_durably when the fault latches and removed
// (the folder fsync'd) when it is acknowledged. One `key = value` per line, `#` comments:
//   kind = fault              fault | overrun_stop
//   fault = drive_fault       a name of the fault table other than none
//   axis = carriage           optional: [a-z0-9_], at most 32 characters
//   device_code = 0x7310      optional: 0x0000..0xFFFF
//   latched_at = 2026-11-26T20:50:03Z
//   rows = 3                  picks, beats likewise: whole numbers 0..4294967295
//   text = a servo drive reported a fault    optional: printable, at most 200 bytes
// Anything else — an unknown or repeated key, a value out of range, a missing fault or latched_at, a
// file that is not a regular file of at most 4 KiB — is refused with a ConfigError naming the
// file:line, the field and the value; nothing is re-latched from it and the file is left as it is.
// Non-RT: the reporter writes it, the service's thread reads and clears it between sessions.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "loom/firmware/serve/fault_history.hpp"
#include "loom/sequencer/faults.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::firmware::serve {

struct LatchedFault {
  sequencer::Fault fault = sequencer::Fault::kNone;
  FaultRecord record;  // kind, name, code, axis, device_code, rows, picks, beats, text (no loom_id)
  std::int64_t latched_at_s = 0;  // UTC seconds since the epoch
};

class LatchedFaultStore {
 public:
  // `reserve`: room kept beside it (durable_file.hpp) that a save on a full disk frees first — a fault
  // latched because the counters could not be saved is still kept, and latched again after a restart.
  LatchedFaultStore(std::string path, std::string reserve_path)
      : path_(std::move(path)), reserve_(std::move(reserve_path)) {}
  // Missing file → nullopt (no fault was latched). Anything else that is not a valid record → ConfigError.
  std::optional<LatchedFault> load() const;
  // Throws std::runtime_error naming the path on failure (the previous file stays); on a full disk the
  // reserve is released first and the save tried again.
  void save(const LatchedFault& f) const;
  // Arming: the reserve is there (made when missing). Throws std::runtime_error when the disk cannot hold it.
  void keep_reserve() const { reserve_.ensure(); }
  // Removes the record (acknowledged). A missing file is not an error. Throws std::runtime_error.
  void clear() const;
  const std::string& path() const { return path_; }
  const std::string& reserve_path() const { return reserve_.path(); }

  static std::string format(const LatchedFault& f);
  static LatchedFault parse(const std::string& text, const std::string& source);
  // "2026-11-26T20:50:03Z"
  static std::string utc(std::int64_t unix_s);

 private:
  std::string path_;
  state::DiskReserve reserve_;
};

}  // namespace loom::firmware::serve
