// One text line per telemetry message, the format technicians grep and scripts parse:
// key=value fields separated by single spaces, STATUS lines first-field loom=, others tagged.
// Kept apart from main.cpp so the exact format is unit-tested.
#pragma once

#include <string>

#include "loomlcm/axes_t.hpp"
#include "loomlcm/rt_stats_t.hpp"
#include "loomlcm/status_t.hpp"

namespace loom::monitor {

// loom=<id> tick=<n> t=<s.mmm>s state=<name> row=<n> pick=<n> beat=<n> fault=<name|none> fault_code=<n>
std::string status_line(const loomlcm::status_t& m);
// axes loom=<id> tick=<n> t=<s>s crank_phase=<rad> beater=<rad> force=<N>N then per axis
// " | <name> pos=.. vel=.. tgt=.. ferr=.. eff=.. drive=<state>"
std::string axes_line(const loomlcm::axes_t& m);
// rt loom=<id> tick=<n> t=<s>s overruns=<n> tick_cost_us=<us> max_tick_cost_us=<us> dropped=<n> backlog=<n>
std::string rt_line(const loomlcm::rt_stats_t& m);

// Received text is printed only after replacing spaces and non-printable bytes with '?', so a
// malformed or hostile message cannot break the one-line, space-separated format.
std::string printable_field(const std::string& s);

}  // namespace loom::monitor
