// LCM channel names for one loom: <prefix>.<loom id>.STATUS / .AXES / .RT (samples, decimated) and
// .BEAT / .FAULT / .ROW / .WEAVER / .COMMAND (events, each sent once), .DESIGN (the weaver's next row, when
// the recipe names a design), .KNOTS (the knotting heads' progress, looms with heads) and .JOB / .CARPET
// (the carpet job and its knot map, from serve). The loom id is in
// the name so a hall of looms can share one multicast group and a technician can subscribe to one loom or
// all.
#pragma once

#include <string>
#include <string_view>

namespace loom::telemetry {

inline constexpr std::string_view kDefaultChannelPrefix = "LOOM";
inline constexpr std::size_t kMaxLoomIdLength = 32;

// Configure-time only. "" when `id` is usable as a loom id (1..32 of A-Z a-z 0-9 _ -), otherwise a
// one-line reason that quotes the value. Dots are refused because they separate channel fields.
std::string loom_id_error(std::string_view id);

// Configure-time only. "" when `prefix` is usable (dot-separated non-empty fields of A-Z a-z 0-9 _ -),
// otherwise a one-line reason that quotes the value.
std::string channel_prefix_error(std::string_view prefix);

struct ChannelNames {
  std::string status;
  std::string axes;
  std::string rt;
  std::string beat;  // events, never decimated
  std::string fault;
  std::string row;
  std::string design;    // the weaver's next row, from the publisher (looms with a design only)
  std::string identity;  // who publishes (host, pid, instance): one loom id, one publisher
  std::string knots;     // the knotting heads' progress, with STATUS (looms with heads only)
  std::string weaver;    // each request the knotting heads make of the weaver (event)
  std::string command;   // the audit of each operator command: who gave it, the reply (event, from serve)
  std::string job;       // the carpet job queue and the current job's progress (low rate, from serve)
  std::string carpet;    // the current job's knot map in bands of rows (at arming and every 10 s, from serve)
};

// Every channel kind, in the order a reader lists them.
inline constexpr std::string_view kChannelKinds[] = {
    "STATUS", "AXES", "RT", "BEAT", "FAULT", "ROW", "DESIGN", "KNOTS", "WEAVER", "COMMAND", "JOB", "CARPET"};

// Configure-time only (allocates). Assumes both parts passed the checks above.
ChannelNames channel_names(std::string_view prefix, std::string_view loom_id);

// Configure-time only. An LCM subscription regex for one channel kind ("STATUS", "AXES", …):
// that loom's channel when `loom_id` is non-empty, else the same channel of every loom.
std::string channel_regex(std::string_view prefix, std::string_view loom_id, std::string_view kind);

}  // namespace loom::telemetry
