// One loom id, one publisher. Every publisher says who it is on <prefix>.<id>.IDENTITY (host, pid and a
// random per-process instance; sent with STATUS at most once a second). Before a loom arms, it listens
// on its own channels: an IDENTITY from another instance — or any STATUS at all, from a publisher too
// old to send IDENTITY or from lcm-logplayer replaying a recording onto the live group — means another
// publisher already uses this id, and the loom refuses to arm, naming it. Configure-time only.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "loomlcm/identity_t.hpp"

namespace loom::telemetry {

// This process's random instance (drawn once) and an IDENTITY message for it.
std::int64_t process_instance();
loomlcm::identity_t this_process_identity(const std::string& loom_id, std::int64_t utime);

// Listens on `lcm_url` for `window` to the channels of `loom_id` under `prefix`. Returns "" when no other
// publisher was heard, else who: "host H (pid P, loomctl V)" or a description of the STATUS heard.
// Throws std::invalid_argument when LCM cannot open `lcm_url`.
std::string other_publisher(const std::string& lcm_url, const std::string& prefix, const std::string& loom_id,
                            std::chrono::milliseconds window);

}  // namespace loom::telemetry
