// The run report a user reads after `loomctl weave --report DIR`: DIR/summary.json (per row: time split,
// beats with carriage position and peak force, faults; totals; the scene's effects) and two plots
// beside it — beat force across the width, and a row's timeline. Non-RT, written after the run.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "loom/sequencer/sequencer.hpp"

namespace loom::report {

struct FaultSummary {
  std::string name;
  unsigned code = 0;
  std::string axis;  // "" when not axis-specific
  unsigned device_code = 0;
  double t_s = 0.0;
  std::string stopped_by;
  std::string text;
};

struct RunSummary {
  std::string loom_id;
  std::string scene;
  std::vector<std::string> effects;
  double period_s = 0.002;
  std::vector<sequencer::RowStats> rows;
  std::vector<std::uint32_t> row_picks;  // picks woven in each reported row
  sequencer::Counters counters;
  std::optional<FaultSummary> fault;
  double machine_s = 0.0;
  double wall_s = 0.0;
  double beat_force_min_n = 80.0, beat_force_max_n = 100.0;  // target band drawn on the plot
};

inline constexpr double kManualRowSeconds = 300.0;  // thesis: 2 min shed + pick, 3 min beating, by hand

nlohmann::json to_json(const RunSummary& s);
// Writes summary.json and the plots into `dir` (created if missing). Throws std::runtime_error naming
// the path on failure.
void write_report(const RunSummary& s, const std::string& dir);
// Renders the plots from a summary.json document (also used by `loom-plot`).
void write_plots(const nlohmann::json& summary, const std::string& dir);

}  // namespace loom::report
