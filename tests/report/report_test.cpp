// The run report: summary.json carries what the contract names, force statistics are computed
// from the beats (not copied), a run without a load cell says so, and the plots are valid SVG documents.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "loom/report/run_report.hpp"

using namespace loom;

namespace {
report::RunSummary two_rows() {
  report::RunSummary s;
  s.loom_id = "t";
  s.scene = "unit";
  s.effects = {"ideal", "beat_contact"};
  s.period_s = 0.002;
  for (std::uint32_t r = 1; r <= 2; ++r) {
    sequencer::RowStats row;
    row.row = r;
    row.shed_ticks = 100, row.pick_ticks = 600, row.beat_ticks = 3000, row.total_ticks = 3700;
    row.beats = 3;
    row.force_measured = true;
    for (int k = 0; k < 3; ++k) {
      const auto fk = static_cast<float>(k);
      row.beat[static_cast<std::size_t>(k)] = {0.5f * fk, 80.0f + 5.0f * fk + static_cast<float>(r)};
    }
    s.rows.push_back(row);
    s.row_picks.push_back(1);
  }
  s.counters = {2, 2, 6, 0};
  s.machine_s = 14.8;
  s.wall_s = 0.01;
  return s;
}
}  // namespace

TEST(RunReport, SummaryFollowsTheContract) {
  const nlohmann::json j = report::to_json(two_rows());
  ASSERT_EQ(j.at("rows").size(), 2u);
  const auto& r = j.at("rows")[0];
  for (const char* key : {"row", "time_s", "shed_s", "pick_s", "beat_s", "beats", "faults"}) EXPECT_TRUE(r.contains(key)) << key;
  EXPECT_DOUBLE_EQ(r.at("time_s").get<double>(), 7.4);
  EXPECT_DOUBLE_EQ(r.at("beats")[2].at("x_m").get<double>(), 1.0);
  const auto& f = j.at("totals").at("beat_force_n");
  EXPECT_DOUBLE_EQ(f.at("min").get<double>(), 81.0);
  EXPECT_DOUBLE_EQ(f.at("max").get<double>(), 92.0);
  EXPECT_NEAR(f.at("mean").get<double>(), (81 + 86 + 91 + 82 + 87 + 92) / 6.0, 1e-5);
  EXPECT_TRUE(f.at("all_in_target").get<bool>());
  EXPECT_EQ(j.at("effects"), nlohmann::json({"ideal", "beat_contact"}));
  EXPECT_EQ(j.at("result"), "completed");
  EXPECT_NEAR(j.at("totals").at("faster_than_manual").get<double>(), 300.0 / 7.4, 1e-9);
}

TEST(RunReport, FaultAndMissingLoadCellAreExplicit) {
  report::RunSummary s = two_rows();
  for (auto& r : s.rows) r.force_measured = false;
  s.fault = report::FaultSummary{"drive_fault", 0x1002, "carriage", 0x8611, 12.0, "drive_fault", "a drive"};
  const nlohmann::json j = report::to_json(s);
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
}

TEST(RunReport, WritesSummaryAndSvgPlots) {
  const auto dir = std::filesystem::temp_directory_path() / "loom_report_test";
  std::filesystem::remove_all(dir);
  report::write_report(two_rows(), dir.string());
  for (const char* f : {"summary.json", "beat_force.svg", "row_timeline.svg"}) {
    ASSERT_TRUE(std::filesystem::exists(dir / f)) << f;
  }
  std::ifstream svg(dir / "beat_force.svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.rfind("<svg", 0), 0u);
  EXPECT_NE(text.find("</svg>"), std::string::npos);
  EXPECT_NE(text.find("<circle"), std::string::npos);  // the beats are drawn
}
