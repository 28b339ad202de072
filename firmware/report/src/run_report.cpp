// rows.jsonl, summary.json and their plots, in constant memory (see run_report.hpp).
#include "loom/report/run_report.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <stdexcept>

#include "loom/report/svg_chart.hpp"

namespace loom::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::size_t kForceRowsDrawn = 8;       // beat-force series: the last rows
constexpr std::size_t kTimelineRowsDrawn = 200;  // timeline bars: the last rows

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + p.string());
}

// Reads the rows back one at a time; memory is one row.
template <typename F>
void for_each_row(const fs::path& rows_path, F&& f) {
  std::ifstream in(rows_path);
  if (!in) throw std::runtime_error("cannot read " + rows_path.string());
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty()) f(line);
  }
}

// Bounded plot state fed one row at a time; the same drawing serves the writer and loom-plot.
class PlotBuilder {
 public:
  void add(const json& row) {
    ++rows_;
    if (!row.value("complete", true)) {
      incomplete_ = true;
      incomplete_row_ = row.at("row").get<long long>();
    }
    if (row.value("complete", true)) {
      Series s;
      s.label = "row " + std::to_string(row.at("row").get<long long>());
      for (const auto& b : row.at("beats")) {
        if (!b.at("peak_force_n").is_null()) {
          s.points.emplace_back(b.at("x_m").get<double>(), b.at("peak_force_n").get<double>());
        }
      }
      if (!s.points.empty()) {
        ++force_rows_;
        force_.push_back(std::move(s));
        if (force_.size() > kForceRowsDrawn) force_.pop_front();
      }
    }
    // Only what the timeline draws is kept, not the row's beats.
    TimelineRow t;
    t.row = row.at("row").get<long long>();
    t.complete = row.value("complete", true);
    if (t.complete) {
      t.time_s = row.at("time_s").get<double>();
      t.end_s = row.value("end_s", -1.0);
      t.knotting_s = row.value("knotting_s", 0.0) + row.value("weaver_s", 0.0);  // heads: inside the row
      t.weaver_knotting_s = row.value("weaver_knotting_s", 0.0);                 // weaver mode: before it
      knotted_ = knotted_ || t.knotting_s > 0.0 || t.weaver_knotting_s > 0.0;
      t.shed_s = row.at("shed_s").get<double>();
      t.pick_s = row.at("pick_s").get<double>();
      t.beat_s = row.at("beat_s").get<double>();
    }
    for (const auto& f : row.at("faults")) {
      t.faults.emplace_back(f.value("t_s", 0.0), f.value("name", std::string("fault")));
    }
    timeline_.push_back(std::move(t));
    if (timeline_.size() > kTimelineRowsDrawn) timeline_.pop_front();
  }

  void write(const json& summary_head, const std::string& dir) const {
    const std::string scene = summary_head.value("scene", std::string("?"));
    // ---- beat force across the width ----
    Chart force;
    force.zoom_to_data = true;
    force.title = "Peak beat force across the width (" + scene + ")";
    if (force_rows_ > force_.size()) {
      force.title +=
          ", last " + std::to_string(force_.size()) + " of " + std::to_string(force_rows_) + " rows";
    }
    force.x_label = "carriage position x (m)";
    force.y_label = "peak beat force (N)";
    static const char* kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd",
                                     "#8c564b", "#e377c2", "#17becf", "#7f7f7f"};
    std::size_t i = 0;
    for (const auto& s : force_) {
      Series c = s;
      c.colour = kColours[i++ % 8];
      force.series.push_back(std::move(c));
    }
    const json* bf =
        summary_head.contains("totals") ? &summary_head.at("totals").at("beat_force_n") : nullptr;
    const double band_lo = summary_head.value("beat_force_min_n", 80.0),
                 band_hi = summary_head.value("beat_force_max_n", 100.0);
    force.bands.push_back({band_lo, band_hi, "target " + fmt0(band_lo) + "–" + fmt0(band_hi) + " N"});
    if (force.series.empty()) {
      if (bf != nullptr && bf->is_null()) {
        force.title += " — no load cell (scene does not name beat_contact)";
      } else {
        force.title += " — no complete row";
      }
      const json& ff = summary_head.contains("first_fault") ? summary_head.at("first_fault") : json();
      if (ff.is_object()) force.title += " (stopped by " + ff.value("name", std::string("?")) + ")";
    } else if (bf != nullptr && bf->is_object()) {
      force.title += bf->value("all_in_target", false) ? ", all beats in band" : ", BEATS OUTSIDE THE BAND";
    }
    write_text(fs::path(dir) / "beat_force.svg", render_svg(force));

    // ---- every row's timeline ----
    Timeline tl;
    tl.lanes = knotted_ ? std::vector<std::string>{"knotting", "shed", "pick", "beat sweep"}
                        : std::vector<std::string>{"shed", "pick", "beat sweep"};
    tl.height_px = 280;
    const std::uint64_t complete = rows_ - (incomplete_ ? 1 : 0);
    tl.title = rows_ > timeline_.size()
                   ? "Row timeline, last " + std::to_string(timeline_.size()) + " of " +
                         std::to_string(rows_) + " rows"
                   : "Row timeline, " + std::to_string(complete) + (complete == 1 ? " row" : " rows");
    if (incomplete_) tl.title += "; row " + std::to_string(incomplete_row_) + " stopped by a fault";
    double prev_end = 0.0;
    for (const auto& r : timeline_) {
      const std::string label = "row " + std::to_string(r.row);
      if (r.complete) {
        const double end = r.end_s >= 0.0 ? r.end_s : prev_end + r.time_s;
        const double row_start = end - r.time_s;
        // The knotting comes first: the heads' inside the row (with the waits for the weaver's hand), the
        // weaver's own before it (weaver mode). Then shed and pick, which alternate per pick and are drawn
        // as one block each, and the beat sweep, in row order.
        if (r.weaver_knotting_s > 0.0) {
          tl.bars.push_back({"knotting", row_start - r.weaver_knotting_s, row_start, "#8c564b", false, ""});
        }
        if (r.knotting_s > 0.0) {
          tl.bars.push_back({"knotting", row_start, row_start + r.knotting_s, "#8c564b", false, ""});
        }
        const double t0 = row_start + r.knotting_s;
        tl.bars.push_back({"shed", t0, t0 + r.shed_s, "#2ca02c", false, ""});
        tl.bars.push_back({"pick", t0 + r.shed_s, t0 + r.shed_s + r.pick_s, "#1f77b4", false, ""});
        tl.bars.push_back({"beat sweep", t0 + r.shed_s + r.pick_s, t0 + r.shed_s + r.pick_s + r.beat_s,
                           "#d62728", false, label});
        prev_end = end;
      } else {
        // The row a fault stopped: from the end of the last row to the fault, outlined.
        double t_fault = prev_end;
        for (const auto& f : r.faults) t_fault = std::max(t_fault, f.first);
        tl.bars.push_back(
            {"", prev_end, std::max(t_fault, prev_end + 1e-3), "#d62728", true, label + " (incomplete)"});
      }
      for (const auto& f : r.faults) tl.markers.push_back({f.first, f.second, "#d62728"});
    }
    write_text(fs::path(dir) / "row_timeline.svg", render_svg(tl));
  }

 private:
  static std::string fmt0(double v) { return std::to_string(static_cast<long long>(std::lround(v))); }
  struct TimelineRow {
    long long row = 0;
    bool complete = true;
    double time_s = 0.0, end_s = -1.0, shed_s = 0.0, pick_s = 0.0, beat_s = 0.0;
    double knotting_s = 0.0, weaver_knotting_s = 0.0;
    std::vector<std::pair<double, std::string>> faults;  // (t_s, name)
  };
  std::deque<Series> force_;
  std::deque<TimelineRow> timeline_;
  std::uint64_t rows_ = 0, force_rows_ = 0;
  bool incomplete_ = false;
  bool knotted_ = false;  // some row was knotted (its knotting is drawn: most of a knotted row's time)
  long long incomplete_row_ = 0;
};

json fault_json(const FaultSummary& f) {
  return {{"name", f.name}, {"code", f.code},
          {"axis", f.axis}, {"device_code", f.device_code},
          {"t_s", f.t_s},   {"stopped_by", f.stopped_by},
          {"text", f.text}};
}

}  // namespace

json row_json(const sequencer::RowStats& r, std::uint32_t picks, double period_s, double end_s) {
  json beats = json::array();
  for (int k = 0; k < r.beats && k < sequencer::kMaxBeatsPerRow; ++k) {
    const auto& b = r.beat[static_cast<std::size_t>(k)];
    json jb = {{"x_m", b.x_m}};
    jb["peak_force_n"] = r.force_measured ? json(b.peak_force_n) : json(nullptr);
    jb["speed_scale"] = b.speed_scale;  // the beat's crank speed over the recipe's (the beat regulator's)
    beats.push_back(jb);
  }
  const auto secs = [&](hal::Tick t) { return static_cast<double>(t) * period_s; };
  return {{"row", r.row},
          {"complete", true},
          {"time_s", secs(r.total_ticks)},
          // The whole row as the weaver's row compares with it: the weaver's own knotting before it (weaver
          // mode) is outside time_s; the heads' knotting and the waits for the weaver's hand are inside.
          {"whole_row_s", secs(r.total_ticks + r.knotting_ticks)},
          {"knotting_s", secs(r.knot_ticks)},
          {"weaver_s", secs(r.weaver_ticks)},
          {"weaver_knotting_s", secs(r.knotting_ticks)},
          {"knots", {{"tied", r.knots_tied}, {"retried", r.knots_retried}, {"by_hand", r.knots_by_hand}}},
          {"shed_s", static_cast<double>(r.shed_ticks) * period_s},
          {"pick_s", static_cast<double>(r.pick_ticks) * period_s},
          {"beat_s", static_cast<double>(r.beat_ticks) * period_s},
          {"end_s", end_s},
          {"picks", picks},
          {"carriage_steps", r.carriage_steps},
          {"beats", beats},
          {"faults", json::array()}};
}

ReportWriter::ReportWriter(const std::string& dir, RunHeader header) : dir_(dir), header_(std::move(header)) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw std::runtime_error("cannot create report directory " + dir_ + ": " + ec.message());
  const fs::path p = fs::path(dir_) / "rows.jsonl";
  rows_out_ = std::make_unique<std::ofstream>(p, std::ios::trunc);
  if (!*rows_out_) throw std::runtime_error("cannot write " + p.string());
}

ReportWriter::~ReportWriter() = default;

void ReportWriter::add_row(const sequencer::RowStats& r, std::uint32_t picks, double end_s) {
  *rows_out_ << row_json(r, picks, header_.period_s, end_s).dump() << '\n';
  rows_out_->flush();
  if (!*rows_out_) throw std::runtime_error("cannot write " + (fs::path(dir_) / "rows.jsonl").string());
  ++rows_;
  row_time_s_ += static_cast<double>(r.total_ticks) * header_.period_s;
  whole_row_s_ += static_cast<double>(r.total_ticks + r.knotting_ticks) * header_.period_s;
  knots_tied_ += static_cast<std::uint64_t>(r.knots_tied);
  knots_retried_ += static_cast<std::uint64_t>(r.knots_retried);
  knots_by_hand_ += static_cast<std::uint64_t>(r.knots_by_hand);
  knotting_s_ += static_cast<double>(r.knot_ticks) * header_.period_s;
  weaver_s_ += static_cast<double>(r.weaver_ticks + r.knotting_ticks) * header_.period_s;
  last_end_s_ = end_s;
  for (int k = 0; r.force_measured && k < r.beats && k < sequencer::kMaxBeatsPerRow; ++k) {
    const double f = r.beat[static_cast<std::size_t>(k)].peak_force_n;
    force_min_ = force_count_ == 0 ? f : std::min(force_min_, f);
    force_max_ = force_count_ == 0 ? f : std::max(force_max_, f);
    force_sum_ += f;
    ++force_count_;
    if (f >= header_.beat_force_min_n && f <= header_.beat_force_max_n) ++force_in_band_;
  }
}

void ReportWriter::finish(const RunEnd& end) {
  if (end.fault) {
    // The row the fault stopped: not complete, so no times or beats, but its faults are where a
    // reader of the rows looks for them.
    const json stopped = {{"row", end.counters.rows + 1},
                          {"complete", false},
                          {"time_s", nullptr},
                          {"shed_s", nullptr},
                          {"pick_s", nullptr},
                          {"beat_s", nullptr},
                          {"start_s", last_end_s_},
                          {"picks", end.counters.picks_in_row},
                          {"beats", json::array()},
                          {"faults", json::array({{{"name", end.fault->name},
                                                   {"code", end.fault->code},
                                                   {"axis", end.fault->axis},
                                                   {"device_code", end.fault->device_code},
                                                   {"t_s", end.fault->t_s}}})}};
    *rows_out_ << stopped.dump() << '\n';
  }
  rows_out_->close();
  if (rows_out_->fail()) throw std::runtime_error("cannot write " + (fs::path(dir_) / "rows.jsonl").string());

  json totals = {{"rows", end.counters.rows},
                 {"picks", end.counters.picks},
                 {"beats", end.counters.beats},
                 {"rows_this_run", rows_},
                 {"machine_time_s", end.machine_s},
                 {"wall_time_s", end.wall_s},
                 {"speedup_vs_real_time", end.wall_s > 0 ? end.machine_s / end.wall_s : 0.0}};
  if (rows_ > 0) {
    const double n = static_cast<double>(rows_);
    totals["row_time_mean_s"] = row_time_s_ / n;
    // Whole rows against the hand's whole row: the same figure weave prints.
    totals["whole_row_time_mean_s"] = whole_row_s_ / n;
    totals["manual_row_time_s"] = header_.manual_row_s;
    totals["faster_than_manual"] = header_.manual_row_s / (whole_row_s_ / n);
    totals["knots_this_run"] = {{"tied", knots_tied_},
                                {"retried", knots_retried_},
                                {"by_hand", knots_by_hand_},
                                {"knotting_time_s", knotting_s_},
                                {"weaver_time_s", weaver_s_}};
  }
  if (force_count_ > 0) {
    totals["beat_force_n"] = {{"min", force_min_},
                              {"mean", force_sum_ / static_cast<double>(force_count_)},
                              {"max", force_max_},
                              {"spread", force_max_ - force_min_},
                              {"target_min", header_.beat_force_min_n},
                              {"target_max", header_.beat_force_max_n},
                              {"beats_in_target", force_in_band_},
                              {"beats_measured", force_count_},
                              {"all_in_target", force_in_band_ == force_count_}};
  } else {
    totals["beat_force_n"] = nullptr;  // no load cell simulated (the scene does not name beat_contact)
  }
  json head = {{"loom_id", header_.loom_id},
               {"scene", header_.scene},
               {"effects", header_.effects},
               {"period_s", header_.period_s},
               {"beat_force_min_n", header_.beat_force_min_n},
               {"beat_force_max_n", header_.beat_force_max_n},
               {"manual_row_s", header_.manual_row_s},
               {"result", end.fault ? "fault" : "completed"},
               {"first_fault", end.fault ? fault_json(*end.fault) : json(nullptr)},
               {"totals", totals}};

  // summary.json: the head's fields, then "rows" streamed from rows.jsonl one at a time.
  const fs::path rows_path = fs::path(dir_) / "rows.jsonl";
  const fs::path summary_path = fs::path(dir_) / "summary.json";
  std::ofstream out(summary_path, std::ios::trunc);
  std::string h = head.dump(1);
  h.pop_back();  // the closing brace: "rows" follows
  while (!h.empty() && (h.back() == '\n' || h.back() == ' ')) h.pop_back();
  out << h << ",\n \"rows\": [";
  PlotBuilder plots;
  bool first = true;
  for_each_row(rows_path, [&](const std::string& line) {
    out << (first ? "\n  " : ",\n  ") << line;
    first = false;
    plots.add(json::parse(line));
  });
  out << "\n ]\n}\n";
  out.close();
  if (!out) throw std::runtime_error("cannot write " + summary_path.string());
  plots.write(head, dir_);
}

void write_plots(const json& summary, const std::string& dir) {
  PlotBuilder plots;
  for (const auto& row : summary.at("rows")) plots.add(row);
  plots.write(summary, dir);
}

}  // namespace loom::report
