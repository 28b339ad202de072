// A job's production record as the weaver and the office read it: text (the terminal), CSV (a
// spreadsheet: one `item,name,value,detail` line per fact) and JSON (tools and the panel). Times are the
// record's own (seconds of each machine state, wall-clock instants in UTC, ISO 8601).
#pragma once

#include <string>

#include "loom/record/production_record.hpp"

namespace loom::record {

std::string report_text(const JobReport& r);
std::string report_csv(const JobReport& r);
std::string report_json(const JobReport& r);

// "2026-12-06T10:15:42.125Z"
std::string iso_utc(WallNs t);

}  // namespace loom::record
