// The run report a user reads after `loomctl weave --report DIR`, written in constant memory however
// long the run: each row is appended to DIR/rows.jsonl as it completes (one JSON object per line:
// time split, beats with carriage position and peak force, faults), while fixed-size aggregates
// (counts, row time, force min/max/sum, beats in band) are kept. At the end DIR/summary.json is
// written by streaming rows.jsonl back (header, every row, totals from the aggregates, the first
// fault), and the plots are drawn from the same stream with a bounded number of series and bars:
// beat_force.svg (beat force across the width, the last rows, zoomed to the data, target band) and
// row_timeline.svg (every row's shed/pick/beat, the last rows when there are many, fault marker,
// the row a fault stopped drawn as incomplete). Non-RT.
#pragma once

#include <cstdint>
#include <fstream>
#include <memory>
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

// What is known before the first row.
struct RunHeader {
  std::string loom_id;
  std::string scene;
  std::vector<std::string> effects;
  double period_s = 0.002;
  double beat_force_min_n = 80.0, beat_force_max_n = 100.0;  // target band
};

// What is known at the end.
struct RunEnd {
  sequencer::Counters counters;
  std::optional<FaultSummary> fault;
  double machine_s = 0.0;
  double wall_s = 0.0;
};

inline constexpr double kManualRowSeconds = 300.0;  // thesis: 2 min shed + pick, 3 min beating, by hand

// One row as a rows.jsonl / summary.json object. `end_s` is the loop time the row completed at.
nlohmann::json row_json(const sequencer::RowStats& r, std::uint32_t picks, double period_s, double end_s);

class ReportWriter {
 public:
  // Creates `dir` and starts DIR/rows.jsonl (replacing an earlier one). Throws std::runtime_error
  // naming the path when it cannot.
  ReportWriter(const std::string& dir, RunHeader header);
  ~ReportWriter();
  ReportWriter(const ReportWriter&) = delete;
  ReportWriter& operator=(const ReportWriter&) = delete;

  // Non-RT. Appends one completed row (flushed, so a killed run keeps its rows) and updates the
  // aggregates. Memory does not grow with the number of rows.
  void add_row(const sequencer::RowStats& r, std::uint32_t picks, double end_s);
  // Non-RT. Appends the row a fault stopped (if any), writes summary.json and the plots. Throws
  // std::runtime_error naming the path on failure.
  void finish(const RunEnd& end);

  std::uint64_t rows() const { return rows_; }

 private:
  std::string dir_;
  RunHeader header_;
  std::unique_ptr<std::ofstream> rows_out_;
  std::uint64_t rows_ = 0;
  double row_time_s_ = 0.0, last_end_s_ = 0.0;
  std::uint64_t force_count_ = 0, force_in_band_ = 0;
  double force_min_ = 0.0, force_max_ = 0.0, force_sum_ = 0.0;
};

// Draws beat_force.svg and row_timeline.svg into `dir` from a summary.json document (`loom-plot`).
void write_plots(const nlohmann::json& summary, const std::string& dir);

}  // namespace loom::report
