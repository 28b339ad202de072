// summary.json and its plots.
#include "loom/report/run_report.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "loom/report/svg_chart.hpp"

namespace loom::report {
namespace {

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + p.string());
}

}  // namespace

nlohmann::json to_json(const RunSummary& s) {
  using nlohmann::json;
  json rows = json::array();
  double fmin = 1e300, fmax = 0.0, fsum = 0.0, row_time = 0.0;
  std::size_t fcount = 0;
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    const auto& r = s.rows[i];
    json beats = json::array();
    for (int k = 0; k < r.beats && k < sequencer::kMaxBeatsPerRow; ++k) {
      const auto& b = r.beat[static_cast<std::size_t>(k)];
      json jb = {{"x_m", b.x_m}};
      if (r.force_measured) {
        jb["peak_force_n"] = b.peak_force_n;
        fmin = std::min(fmin, static_cast<double>(b.peak_force_n));
        fmax = std::max(fmax, static_cast<double>(b.peak_force_n));
        fsum += b.peak_force_n;
        ++fcount;
      } else {
        jb["peak_force_n"] = nullptr;
      }
      beats.push_back(jb);
    }
    const double t = static_cast<double>(r.total_ticks) * s.period_s;
    row_time += t;
    rows.push_back({{"row", r.row},
                    {"time_s", t},
                    {"shed_s", static_cast<double>(r.shed_ticks) * s.period_s},
                    {"pick_s", static_cast<double>(r.pick_ticks) * s.period_s},
                    {"beat_s", static_cast<double>(r.beat_ticks) * s.period_s},
                    {"complete", true},
                    {"picks", i < s.row_picks.size() ? s.row_picks[i] : 0u},
                    {"carriage_steps", r.carriage_steps},
                    {"beats", beats},
                    {"faults", json::array()}});
  }
  if (s.fault) {
    // The row the fault stopped: not complete, so no times or beats, but its faults are where a
    // reader of the rows looks for them.
    rows.push_back({{"row", s.counters.rows + 1},
                    {"complete", false},
                    {"time_s", nullptr},
                    {"shed_s", nullptr},
                    {"pick_s", nullptr},
                    {"beat_s", nullptr},
                    {"picks", s.counters.picks_in_row},
                    {"beats", json::array()},
                    {"faults", json::array({{{"name", s.fault->name},
                                             {"code", s.fault->code},
                                             {"axis", s.fault->axis},
                                             {"device_code", s.fault->device_code},
                                             {"t_s", s.fault->t_s}}})}});
  }
  json totals = {{"rows", s.counters.rows},
                 {"picks", s.counters.picks},
                 {"beats", s.counters.beats},
                 {"rows_this_run", s.rows.size()},
                 {"machine_time_s", s.machine_s},
                 {"wall_time_s", s.wall_s},
                 {"speedup_vs_real_time", s.wall_s > 0 ? s.machine_s / s.wall_s : 0.0}};
  if (!s.rows.empty()) {
    const double mean = row_time / static_cast<double>(s.rows.size());
    totals["row_time_mean_s"] = mean;
    totals["manual_row_time_s"] = kManualRowSeconds;
    totals["faster_than_manual"] = kManualRowSeconds / mean;
  }
  if (fcount > 0) {
    totals["beat_force_n"] = {{"min", fmin}, {"mean", fsum / static_cast<double>(fcount)}, {"max", fmax},
                              {"spread", fmax - fmin}, {"target_min", s.beat_force_min_n},
                              {"target_max", s.beat_force_max_n},
                              {"all_in_target", fmin >= s.beat_force_min_n && fmax <= s.beat_force_max_n}};
  } else {
    totals["beat_force_n"] = nullptr;  // no load cell simulated (the scene does not name beat_contact)
  }
  json out = {{"loom_id", s.loom_id}, {"scene", s.scene}, {"effects", s.effects}, {"period_s", s.period_s},
              {"rows", rows}, {"totals", totals}};
  if (s.fault) {
    const auto& f = *s.fault;
    out["result"] = "fault";
    out["first_fault"] = {{"name", f.name}, {"code", f.code}, {"axis", f.axis}, {"device_code", f.device_code},
                          {"t_s", f.t_s}, {"stopped_by", f.stopped_by}, {"text", f.text}};
  } else {
    out["result"] = "completed";
    out["first_fault"] = nullptr;
  }
  return out;
}

void write_plots(const nlohmann::json& j, const std::string& dir) {
  namespace fs = std::filesystem;
  // Beat force across the width: one series per row.
  Chart force;
  force.title = "Peak beat force across the width (" + j.value("scene", std::string("?")) + ")";
  force.x_label = "carriage position x (m)";
  force.y_label = "peak beat force (N)";
  static const char* kColours[] = {"#1f77b4", "#ff7f0e", "#d62728", "#9467bd", "#8c564b", "#e377c2"};
  bool any_force = false;
  std::size_t i = 0;
  for (const auto& row : j.at("rows")) {
    if (!row.value("complete", true)) continue;
    Series s;
    s.label = "row " + std::to_string(row.at("row").get<int>());
    s.colour = kColours[i++ % 6];
    for (const auto& b : row.at("beats")) {
      if (!b.at("peak_force_n").is_null()) {
        s.points.emplace_back(b.at("x_m").get<double>(), b.at("peak_force_n").get<double>());
        any_force = true;
      }
    }
    if (!s.points.empty() && force.series.size() < 6) force.series.push_back(std::move(s));
  }
  const auto& bf = j.at("totals").at("beat_force_n");
  if (bf.is_object()) force.bands.push_back({bf.at("target_min").get<double>(), bf.at("target_max").get<double>(), "target"});
  if (!any_force) force.title += " — no load cell (scene does not name beat_contact)";
  write_text(fs::path(dir) / "beat_force.svg", render_svg(force));

  // A row's timeline: the last complete row.
  Timeline tl;
  tl.title = "Row timeline";
  tl.lanes = {"shed", "pick", "beat sweep"};
  const nlohmann::json* last = nullptr;
  for (const auto& row : j.at("rows")) {
    if (row.value("complete", true)) last = &row;
  }
  if (last != nullptr) {
    const auto& r = *last;
    const double shed = r.at("shed_s"), pick = r.at("pick_s"), beat = r.at("beat_s");
    tl.title = "Row " + std::to_string(r.at("row").get<int>()) + " timeline (" + std::to_string(r.at("time_s").get<double>()).substr(0, 5) + " s)";
    tl.bars.push_back({"shed", 0.0, shed, "#2ca02c"});
    tl.bars.push_back({"pick", shed, shed + pick, "#1f77b4"});
    tl.bars.push_back({"beat sweep", shed + pick, shed + pick + beat, "#d62728"});
  }
  write_text(fs::path(dir) / "row_timeline.svg", render_svg(tl));
}

void write_report(const RunSummary& s, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create report directory " + dir + ": " + ec.message());
  const nlohmann::json j = to_json(s);
  write_text(fs::path(dir) / "summary.json", j.dump(2) + "\n");
  write_plots(j, dir);
}

}  // namespace loom::report
