// The COMMAND channel: the audit of each operator command as an LCM event (loomlcm::command_t on
// <prefix>.<id>.COMMAND) — who gave it, from which station, and what the loom answered. Published by
// `loomctl serve` beside the journal and faults.log, so a hall's supervisor (or an lcm-logger) sees who
// set a loom moving. Non-RT: the control socket's and the reporter's threads call publish(); never the
// loop. Its own lcm_t, so it lives as long as the service, across sessions whose publishers come and go.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>

#include "loomlcm/command_t.hpp"

typedef struct _lcm_t lcm_t;

namespace loom::telemetry {

// One command's audit, as the service decided it.
struct CommandAudit {
  std::string word;     // start, pause, resume, stop, ack, next, pair, unpair, redeem
  std::string station;  // "local", "panel", "button"
  std::string who;
  bool accepted = false;
  std::string reply;  // without its trailing newline; the caller has removed secrets
  std::string state;  // the loom's state when decided
};

// Not RT-safe: allocates. The message for `a` (pure, for tests and the publisher).
loomlcm::command_t to_command(const CommandAudit& a, const std::string& loom_id, std::int64_t utime);

class CommandEvents {
 public:
  // Configure-time: opens `lcm_url` ("" = LCM's default). Throws std::invalid_argument when LCM cannot.
  CommandEvents(const std::string& lcm_url, const std::string& prefix, const std::string& loom_id);
  ~CommandEvents();
  CommandEvents(const CommandEvents&) = delete;
  CommandEvents& operator=(const CommandEvents&) = delete;

  // Thread-safe; never throws. Returns false when LCM refused the message (counted in failures()).
  bool publish(const CommandAudit& a) noexcept;
  std::uint64_t published() const;
  std::uint64_t failures() const;
  const std::string& channel() const { return channel_; }

 private:
  lcm_t* lcm_ = nullptr;
  std::string channel_;
  std::string loom_id_;
  mutable std::mutex mu_;
  std::uint64_t published_ = 0, failures_ = 0;
};

}  // namespace loom::telemetry
