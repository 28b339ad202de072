// The persistent fault history: lines appended survive a reopen, read back oldest first, and the file
// is bounded — rotation keeps one generation, so the history never exceeds twice the limit and always
// holds the newest lines.
#include "loom/firmware/serve/fault_history.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "loom/firmware/serve/journal.hpp"
#include "test_dir.hpp"

using namespace loom::firmware::serve;

namespace {
std::string temp_dir() {
  return loom::test::fresh_test_dir("fh").string();
}
FaultRecord record(std::uint32_t rows) {
  FaultRecord r;
  r.loom_id = "loom1";
  r.name = "drive_fault";
  r.code = 0x1002;
  r.axis = "carriage";
  r.device_code = 0x7310;
  r.rows = rows;
  r.picks = rows;
  r.beats = 15 * rows;
  r.text = "a servo drive reported a fault";
  return r;
}
}  // namespace

TEST(FaultHistory, FormatNamesEverythingATechnicianNeeds) {
  EXPECT_EQ(FaultHistory::format(record(3), 1'795'000'000),
            "2026-11-18T11:06:40Z fault loom1 drive_fault 0x1002 axis=carriage device=0x7310 rows=3 picks=3 "
            "beats=45: "
            "a servo drive reported a fault");
}

TEST(FaultHistory, AppendedLinesSurviveAReopen) {
  const std::string dir = temp_dir();
  {
    FaultHistory h(dir + "/faults.log");
    h.append(record(1));
    h.append(record(2));
  }
  FaultHistory again(dir + "/faults.log");
  const auto lines = again.read_all();
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[0].find("rows=1 "), std::string::npos);
  EXPECT_NE(lines[1].find("rows=2 "), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(FaultHistory, RotationBoundsTheSizeAndKeepsTheNewest) {
  const std::string dir = temp_dir();
  const std::uint64_t limit = 1000;
  FaultHistory h(dir + "/faults.log", limit);
  for (std::uint32_t i = 1; i <= 100; ++i) h.append(record(i));
  const auto size = std::filesystem::file_size(dir + "/faults.log");
  const auto size1 = std::filesystem::file_size(dir + "/faults.log.1");
  EXPECT_LE(size, limit);
  EXPECT_LE(size1, limit);
  const auto lines = h.read_all();
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines.back().find("rows=100 "), std::string::npos);
  // Oldest first and contiguous: rows increase by one along the kept lines.
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto rows = [](const std::string& l) { return std::stoul(l.substr(l.find("rows=") + 5)); };
    EXPECT_EQ(rows(lines[i]), rows(lines[i - 1]) + 1);
  }
  EXPECT_LT(lines.size(), 100u);
  std::filesystem::remove_all(dir);
}

TEST(FaultHistory, UnwritableFileIsAnErrorNamingIt) {
  FaultHistory h("/nonexistent-dir/faults.log");
  try {
    h.append(record(1));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/faults.log"), std::string::npos) << e.what();
  }
}

TEST(Journal, SeverityPrefixIsTheSdDaemonForm) {
  EXPECT_EQ(journal_line(Severity::kErr, "FAULT estop", true), "<3>FAULT estop");
  EXPECT_EQ(journal_line(Severity::kNotice, "armed", true), "<5>armed");
  EXPECT_EQ(journal_line(Severity::kWarning, "degraded", false), "WARNING: degraded");
  EXPECT_EQ(journal_line(Severity::kInfo, "row 1 done", false), "row 1 done");
}
