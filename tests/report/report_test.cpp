// The run report: rows streamed to rows.jsonl, summary.json carrying what the contract names with
// force statistics computed from the beats (not copied), a run without a load cell and a faulted run
// saying so, and plots that are valid SVG documents zoomed to the data with every row drawn.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "loom/report/run_report.hpp"

using namespace loom;

namespace {

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("loom_report_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

std::string read(const std::filesystem::path& p) {
  std::ifstream f(p);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

sequencer::RowStats row(std::uint32_t r, bool measured = true) {
  sequencer::RowStats s;
  s.row = r;
  s.shed_ticks = 100, s.pick_ticks = 600, s.beat_ticks = 3000, s.total_ticks = 3700;
  s.beats = 3;
  s.force_measured = measured;
  for (int k = 0; k < 3; ++k) {
    const auto fk = static_cast<float>(k);
    s.beat[static_cast<std::size_t>(k)] = {0.5f * fk, 80.0f + 5.0f * fk + static_cast<float>(r)};
  }
  return s;
}

report::RunHeader header() {
  report::RunHeader h;
  h.loom_id = "t";
  h.scene = "unit";
  h.effects = {"ideal", "beat_contact"};
  h.period_s = 0.002;
  return h;
}

nlohmann::json two_rows(const std::filesystem::path& dir, bool measured,
                        std::optional<report::FaultSummary> fault) {
  report::ReportWriter w(dir.string(), header());
  w.add_row(row(1, measured), 1, 7.4);
  w.add_row(row(2, measured), 1, 14.8);
  report::RunEnd end;
  end.counters = {2, 2, 6, 0};
  end.machine_s = fault ? 16.0 : 14.8;
  end.wall_s = 0.01;
  end.fault = fault;
  w.finish(end);
  return nlohmann::json::parse(read(dir / "summary.json"));
}

}  // namespace

TEST(RunReport, SummaryFollowsTheContract) {
  const auto dir = fresh_dir("contract");
  const nlohmann::json j = two_rows(dir, true, std::nullopt);
  ASSERT_EQ(j.at("rows").size(), 2u);
  const auto& r = j.at("rows")[0];
  for (const char* key : {"row", "time_s", "shed_s", "pick_s", "beat_s", "beats", "faults", "end_s"}) {
    EXPECT_TRUE(r.contains(key)) << key;
  }
  EXPECT_DOUBLE_EQ(r.at("time_s").get<double>(), 7.4);
  EXPECT_DOUBLE_EQ(r.at("beats")[2].at("x_m").get<double>(), 1.0);
  const auto& f = j.at("totals").at("beat_force_n");
  EXPECT_DOUBLE_EQ(f.at("min").get<double>(), 81.0);
  EXPECT_DOUBLE_EQ(f.at("max").get<double>(), 92.0);
  EXPECT_NEAR(f.at("mean").get<double>(), (81 + 86 + 91 + 82 + 87 + 92) / 6.0, 1e-5);
  EXPECT_TRUE(f.at("all_in_target").get<bool>());
  EXPECT_EQ(f.at("beats_in_target"), 6);
  EXPECT_EQ(j.at("effects"), nlohmann::json({"ideal", "beat_contact"}));
  EXPECT_EQ(j.at("result"), "completed");
  EXPECT_NEAR(j.at("totals").at("faster_than_manual").get<double>(), 300.0 / 7.4, 1e-9);
  // rows.jsonl holds the same rows, one JSON object per line.
  std::ifstream rows(dir / "rows.jsonl");
  std::string line;
  int n = 0;
  while (std::getline(rows, line))
    EXPECT_EQ(nlohmann::json::parse(line), j.at("rows")[static_cast<std::size_t>(n++)]);
  EXPECT_EQ(n, 2);
}

TEST(RunReport, FaultAndMissingLoadCellAreExplicit) {
  const auto dir = fresh_dir("fault");
  const nlohmann::json j = two_rows(
      dir, false,
      report::FaultSummary{"drive_fault", 0x1002, "carriage", 0x8611, 16.0, "drive_fault", "a drive"});
  EXPECT_TRUE(j.at("totals").at("beat_force_n").is_null());
  EXPECT_TRUE(j.at("rows")[0].at("beats")[0].at("peak_force_n").is_null());
  EXPECT_EQ(j.at("result"), "fault");
  EXPECT_EQ(j.at("first_fault").at("name"), "drive_fault");
  // The stopped row is listed, incomplete, with its fault.
  ASSERT_EQ(j.at("rows").size(), 3u);
  EXPECT_FALSE(j.at("rows")[2].at("complete").get<bool>());
  EXPECT_EQ(j.at("rows")[2].at("row"), 3);
  EXPECT_EQ(j.at("rows")[2].at("faults")[0].at("name"), "drive_fault");
  EXPECT_TRUE(j.at("rows")[1].at("faults").empty());
  // The timeline draws the stopped row as incomplete and marks the fault.
  const std::string tl = read(dir / "row_timeline.svg");
  EXPECT_NE(tl.find("row 3 (incomplete)"), std::string::npos);
  EXPECT_NE(tl.find("stroke-dasharray"), std::string::npos);
  EXPECT_NE(tl.find(">drive_fault</text>"), std::string::npos);
  EXPECT_NE(read(dir / "beat_force.svg").find("no load cell"), std::string::npos);
}

TEST(RunReport, PlotsAreZoomedToTheDataWithOneSeriesPerRow) {
  const auto dir = fresh_dir("plots");
  two_rows(dir, true, std::nullopt);
  const std::string text = read(dir / "beat_force.svg");
  EXPECT_EQ(text.rfind("<svg", 0), 0u);
  EXPECT_NE(text.find("</svg>"), std::string::npos);
  EXPECT_NE(text.find(">row 1</text>"), std::string::npos);
  EXPECT_NE(text.find(">row 2</text>"), std::string::npos);
  EXPECT_EQ(text.find("text-anchor='end'>0</text>"),
            std::string::npos);  // the force axis does not start at 0 N
  EXPECT_NE(text.find("target 80–100 N"), std::string::npos);
  // Every row is on the timeline.
  const std::string tl = read(dir / "row_timeline.svg");
  EXPECT_NE(tl.find(">row 1</text>"), std::string::npos);
  EXPECT_NE(tl.find(">row 2</text>"), std::string::npos);
  // loom-plot's path draws the same from summary.json.
  const auto again = fresh_dir("plots_again");
  std::filesystem::create_directories(again);
  report::write_plots(nlohmann::json::parse(read(dir / "summary.json")), again.string());
  EXPECT_EQ(read(again / "beat_force.svg"), text);
  EXPECT_EQ(read(again / "row_timeline.svg"), tl);
}

TEST(RunReport, ManyRowsDrawABoundedNumberOfSeries) {
  const auto dir = fresh_dir("many");
  report::ReportWriter w(dir.string(), header());
  for (std::uint32_t r = 1; r <= 500; ++r) w.add_row(row(r), 1, 7.4 * r);
  report::RunEnd end;
  end.counters = {500, 500, 1500, 0};
  w.finish(end);
  const std::string bf = read(dir / "beat_force.svg");
  EXPECT_NE(bf.find("last 8 of 500 rows"), std::string::npos);
  EXPECT_EQ(bf.find(">row 492</text>"), std::string::npos);
  EXPECT_NE(bf.find(">row 493</text>"), std::string::npos);
  EXPECT_NE(read(dir / "row_timeline.svg").find("last 200 of 500 rows"), std::string::npos);
}

TEST(RunReport, UnwritableDirectoryIsNamed) {
  try {
    report::ReportWriter w("/proc/loom_no_such_dir/x", header());
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/proc/loom_no_such_dir/x"), std::string::npos);
  }
}

// A knotted run: each row carries its knots and knotting times, the totals compare whole rows with the
// weaver's whole row (the heads' knotting inside the row, the weaver's own before it — the same figure weave
// prints), and the timeline draws the knotting, most of a knotted row.
TEST(RunReport, KnottedRowsCarryTheirKnotsAndCompareWholeRows) {
  const auto dir = fresh_dir("knotted");
  report::RunHeader h = header();
  h.manual_row_s = report::kManualKnottedRowSeconds;
  report::ReportWriter w(dir.string(), h);
  sequencer::RowStats a = row(1);
  a.knot_ticks = 25000, a.weaver_ticks = 5000, a.total_ticks = 3700 + 30000;  // heads: inside the row
  a.knots_tied = 358, a.knots_retried = 4, a.knots_by_hand = 2;
  sequencer::RowStats b = row(2);
  b.knotting_ticks = 60000;  // weaver mode: the weaver knotted 120 s before the row
  w.add_row(a, 1, 67.4);
  w.add_row(b, 1, 194.8);
  report::RunEnd end;
  end.counters = {2, 2, 6, 0};
  end.machine_s = 194.8;
  end.wall_s = 1.0;
  w.finish(end);
  const nlohmann::json j = nlohmann::json::parse(read(dir / "summary.json"));
  const auto& r0 = j.at("rows")[0];
  EXPECT_EQ(r0.at("knots").at("tied"), 358);
  EXPECT_EQ(r0.at("knots").at("retried"), 4);
  EXPECT_EQ(r0.at("knots").at("by_hand"), 2);
  EXPECT_DOUBLE_EQ(r0.at("knotting_s").get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(r0.at("weaver_s").get<double>(), 10.0);
  EXPECT_DOUBLE_EQ(r0.at("whole_row_s").get<double>(), 67.4);
  EXPECT_DOUBLE_EQ(j.at("rows")[1].at("whole_row_s").get<double>(), 7.4 + 120.0);
  const auto& t = j.at("totals");
  const double whole = (67.4 + 127.4) / 2.0;
  EXPECT_NEAR(t.at("whole_row_time_mean_s").get<double>(), whole, 1e-9);
  EXPECT_EQ(t.at("manual_row_time_s"), 600.0);
  EXPECT_NEAR(t.at("faster_than_manual").get<double>(), 600.0 / whole, 1e-9);
  EXPECT_EQ(t.at("knots_this_run").at("tied"), 358);
  EXPECT_EQ(t.at("knots_this_run").at("by_hand"), 2);
  EXPECT_NEAR(t.at("knots_this_run").at("weaver_time_s").get<double>(), 10.0 + 120.0, 1e-9);
  const std::string svg = read(dir / "row_timeline.svg");
  EXPECT_NE(svg.find("knotting"), std::string::npos) << "the timeline has no knotting lane";
}
