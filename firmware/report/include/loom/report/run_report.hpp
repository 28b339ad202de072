// The run report a user reads after `loomctl weave --report DIR`, written in constant memory however
// long the run: each row is appended to DIR/rows.jsonl as it completes (one JSON object per line:
// time split, the knots (by the heads, retried, by hand) and the knotting and weaver's time, beats with
// carriage position and peak force, faults), while fixed-size aggregates
// (counts, row time, force min/max/sum, beats in band) are kept. At the end DIR/summary.json is
// written by streaming rows.jsonl back (header, every row, totals from the aggregates, the first
// fault), and the plots are drawn from the same stream with a bounded number of series and bars:
// beat_force.svg (beat force across the width, the last rows, zoomed to the data, target band) and
// row_timeline.svg (every row's knotting/shed/pick/beat, the last rows when there are many, fault marker,
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
  // The hand's time for the same whole row (thesis ch. 6): a knotted row ~600 s (5 min knotting, 2 shedding
  // and picking, 3 beating), a flat-woven row ~300 s (shed, pick and beat only). kManualRowSeconds*.
  double manual_row_s = 300.0;
};

// What is known at the end.
struct RunEnd {
  sequencer::Counters counters;
  std::optional<FaultSummary> fault;
  double machine_s = 0.0;
  double wall_s = 0.0;
};

inline constexpr double kManualRowSeconds = 300.0;  // thesis: 2 min shed + pick, 3 min beating, by hand
inline constexpr double kManualKnottedRowSeconds = 600.0;  // ... plus ~5 min knotting the row

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
  double whole_row_s_ = 0.0;  // the rows' time plus the weaver's knotting before each (weaver mode)
  std::uint64_t knots_tied_ = 0, knots_retried_ = 0, knots_by_hand_ = 0;
  double knotting_s_ = 0.0, weaver_s_ = 0.0;
  std::uint64_t force_count_ = 0, force_in_band_ = 0;
  double force_min_ = 0.0, force_max_ = 0.0, force_sum_ = 0.0;
};

// Draws beat_force.svg and row_timeline.svg into `dir` from a summary.json document (`loom-plot`).
void write_plots(const nlohmann::json& summary, const std::string& dir);

}  // namespace loom::report
