// Counters that cannot lie: unreadable is not absent, values are whole 32-bit counts (never rounded or
// wrapped), the counts agree with each other, a counters file that cannot be written refuses to arm,
// and a save that fails mid-run stops the loom at the end of the row with a named fault.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "cli_run.hpp"
#include "loom/config/config.hpp"
#include "loom/state/counter_store.hpp"

using namespace loom::firmware;
namespace fs = std::filesystem;

namespace {

std::string parse_error(const std::string& text) {
  try {
    (void)loom::state::CounterStore::parse(text, "c.json");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

using loom::test::CliRun;
CliRun run_loomctl(const std::string& args) {
  return loom::test::run_command(std::string(LOOMCTL_PATH) + " " + args);
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("loom_counters_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(Counters, RoundTripAndStrictShape) {
  const loom::sequencer::Counters c{7, 9, 105, 2};
  const loom::sequencer::Counters back =
      loom::state::CounterStore::parse(loom::state::CounterStore::format(c), "c.json");
  EXPECT_EQ(back.rows, 7u);
  EXPECT_EQ(back.picks, 9u);
  EXPECT_EQ(back.beats, 105u);
  EXPECT_EQ(back.picks_in_row, 2u);
  EXPECT_EQ(loom::state::CounterStore::parse(
                " { \"picks_in_row\" : 0 , \"beats\":4294967295,\"rows\":1,\"picks\":1}\n", "c")
                .beats,
            4294967295u);
}

TEST(Counters, TheKnottingHeadsCountsComeTogetherAndAgree) {
  loom::sequencer::Counters c{4, 8, 60, 0, {}};
  // A loom without heads writes what it always wrote.
  EXPECT_EQ(loom::state::CounterStore::format(c),
            "{\"rows\":4,\"picks\":8,\"beats\":60,\"picks_in_row\":0}\n");
  c.knot = {1400, 12, 3, 17, 16};
  const std::string text = loom::state::CounterStore::format(c);
  EXPECT_NE(text.find("\"knots\":1400,\"knots_retried\":12,\"knots_by_hand\":3,\"knot_cycles_started\":17,"
                      "\"knot_cycles_done\":16"),
            std::string::npos)
      << text;
  const loom::sequencer::Counters back = loom::state::CounterStore::parse(text, "c.json");
  EXPECT_EQ(back.knot.tied, 1400u);
  EXPECT_EQ(back.knot.retried, 12u);
  EXPECT_EQ(back.knot.by_hand, 3u);
  EXPECT_EQ(back.knot.cycles_started, 17u);
  EXPECT_EQ(back.knot.cycles_done, 16u);
  // All five or none; a cycle done that never started is not loomctl's.
  EXPECT_NE(parse_error("{\"rows\":4,\"picks\":8,\"beats\":60,\"picks_in_row\":0,\"knots\":5}")
                .find("the knot counts come together"),
            std::string::npos);
  EXPECT_NE(
      parse_error("{\"rows\":4,\"picks\":8,\"beats\":60,\"picks_in_row\":0,\"knots\":5,\"knots_retried\":0,"
                  "\"knots_by_hand\":0,\"knot_cycles_started\":2,\"knot_cycles_done\":3}")
          .find("knot_cycles_done = 3 exceeds knot_cycles_started = 2"),
      std::string::npos);
}

// The row in progress's own knot tallies (the production record's row after a power cut): written only
// while a row is partly knotted, read back, and never more than the totals.
TEST(Counters, TheRowInProgressKeepsItsKnotsAcrossARestart) {
  loom::sequencer::Counters c{4, 8, 60, 0, {}};
  c.knot = {1400, 12, 3, 17, 16, 0, 40, 2, 1};
  const std::string text = loom::state::CounterStore::format(c);
  EXPECT_NE(text.find("\"row_knots\":40,\"row_knots_retried\":2,\"row_knots_by_hand\":1"), std::string::npos)
      << text;
  const loom::sequencer::Counters back = loom::state::CounterStore::parse(text, "c.json");
  EXPECT_EQ(back.knot.row_tied, 40u);
  EXPECT_EQ(back.knot.row_retried, 2u);
  EXPECT_EQ(back.knot.row_by_hand, 1u);
  c.knot.row_tied = c.knot.row_retried = c.knot.row_by_hand = 0;
  EXPECT_EQ(loom::state::CounterStore::format(c).find("row_knots"),
            std::string::npos);  // between rows: as before
  EXPECT_NE(
      parse_error("{\"rows\":4,\"picks\":8,\"beats\":60,\"picks_in_row\":0,\"knots\":5,\"knots_retried\":0,"
                  "\"knots_by_hand\":0,\"knot_cycles_started\":2,\"knot_cycles_done\":1,\"row_knots\":6,"
                  "\"row_knots_retried\":0,\"row_knots_by_hand\":0}")
          .find("exceed the totals (knots 5"),
      std::string::npos);
}

TEST(Counters, ValuesAreWholeCountsNeverRoundedOrWrapped) {
  const auto bad = [](const std::string& rows) {
    return parse_error("{\"rows\":" + rows + ",\"picks\":5,\"beats\":5,\"picks_in_row\":0}");
  };
  EXPECT_NE(bad("1.5").find("\"rows\" = 1.5: must be a whole number"), std::string::npos) << bad("1.5");
  EXPECT_NE(bad("-1").find("must be a whole number"), std::string::npos) << bad("-1");
  EXPECT_NE(bad("1e3").find("must be a whole number"), std::string::npos) << bad("1e3");
  EXPECT_NE(bad("007").find("must be a whole number"), std::string::npos) << bad("007");
  EXPECT_NE(bad("4294967296").find("beyond 4294967295"), std::string::npos) << bad("4294967296");
  EXPECT_NE(bad("9999999999").find("beyond 4294967295"), std::string::npos) << bad("9999999999");
  EXPECT_NE(bad("\"3\"").find("must be a whole number"), std::string::npos);
}

TEST(Counters, ShapeErrorsAreNamed) {
  EXPECT_NE(parse_error("{\"rows\":1,\"picks\":1,\"beats\":1}").find("lacks \"picks_in_row\""),
            std::string::npos);
  EXPECT_NE(
      parse_error("{\"rows\":1,\"rows\":1,\"picks\":1,\"beats\":1,\"picks_in_row\":0}").find("given twice"),
      std::string::npos);
  EXPECT_NE(parse_error("{\"rows\":1,\"picks\":1,\"beats\":1,\"picks_in_row\":0,\"spare\":1}")
                .find("unknown field"),
            std::string::npos);
  EXPECT_NE(parse_error("{\"rows\":1,\"picks\":1,\"beats\":1,\"picks_in_row\":0} x").find("trailing text"),
            std::string::npos);
  EXPECT_NE(parse_error("").find("expected '{'"), std::string::npos);
}

TEST(Counters, CountsThatContradictEachOtherAreRefused) {
  EXPECT_NE(parse_error("{\"rows\":5,\"picks\":3,\"beats\":75,\"picks_in_row\":0}").find("contradict"),
            std::string::npos);
  EXPECT_NE(parse_error("{\"rows\":5,\"picks\":5,\"beats\":75,\"picks_in_row\":1}").find("contradict"),
            std::string::npos);
  EXPECT_NE(parse_error("{\"rows\":5,\"picks\":5,\"beats\":4,\"picks_in_row\":0}").find("contradict"),
            std::string::npos);
}

TEST(Counters, MissingStartsFromZeroButUnreadableIsAnError) {
  const fs::path d = temp_dir("load");
  EXPECT_FALSE(loom::state::CounterStore((d / "none.json").string()).load().has_value());
  // A directory where the file should be: it exists, and cannot be a counters file.
  fs::create_directories(d / "dir.json");
  EXPECT_THROW((void)loom::state::CounterStore((d / "dir.json").string()).load(), ConfigError);
  fs::remove_all(d);
}

TEST(Counters, FailedSaveThrowsAndLeavesThePreviousFile) {
  const fs::path d = temp_dir("save");
  const loom::state::CounterStore store((d / "c.json").string());
  store.save({1, 1, 15, 0});
  fs::create_directories(d / "c.json.tmp");  // the temp file cannot be created now
  EXPECT_THROW(store.save({2, 2, 30, 0}), std::runtime_error);
  EXPECT_EQ(slurp(d / "c.json"), "{\"rows\":1,\"picks\":1,\"beats\":15,\"picks_in_row\":0}\n");
  EXPECT_THROW(loom::state::CounterStore((d / "no" / "c.json").string()).save({}), std::runtime_error);
  fs::remove_all(d);
}

TEST(CountersCli, UnreadableCountersExit2AndTheFileIsUntouched) {
  const fs::path d = temp_dir("cli_bad");
  std::ofstream(d / "c.json") << "{\"rows\":1.5,\"picks\":2,\"beats\":30,\"picks_in_row\":0}\n";
  const CliRun r = run_loomctl("weave --rows 1 --no-telemetry --counters " + (d / "c.json").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("must be a whole number"), std::string::npos) << r.output;
  EXPECT_EQ(slurp(d / "c.json"), "{\"rows\":1.5,\"picks\":2,\"beats\":30,\"picks_in_row\":0}\n");
  fs::remove_all(d);
}

TEST(CountersCli, RowsNearTheCounterRangeAreRefusedNotWrapped) {
  const fs::path d = temp_dir("cli_wrap");
  std::ofstream(d / "c.json")
      << "{\"rows\":4294967295,\"picks\":4294967295,\"beats\":4294967295,\"picks_in_row\":0}\n";
  const CliRun r = run_loomctl("weave --rows 1 --no-telemetry --counters " + (d / "c.json").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("never wrapped"), std::string::npos) << r.output;
  fs::remove_all(d);
}

TEST(CountersCli, PicksInRowBeyondTheRecipeAreNotThisLoomsCounters) {
  const fs::path d = temp_dir("cli_pir");
  std::ofstream(d / "c.json") << "{\"rows\":2,\"picks\":101,\"beats\":30,\"picks_in_row\":99}\n";
  const CliRun r = run_loomctl("weave --rows 1 --no-telemetry --counters " + (d / "c.json").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("picks_in_row = 99"), std::string::npos) << r.output;
  fs::remove_all(d);
}

TEST(CountersCli, ACountersFileThatCannotBeWrittenRefusesToArm) {
  const CliRun r = run_loomctl("weave --rows 1 --no-telemetry --counters /nonexistent-loom-dir/c.json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("cannot be written, refusing to arm"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("row 1"), std::string::npos) << r.output;
}

TEST(CountersCli, ASaveThatFailsMidRunStopsAtTheRowEndWithANamedFault) {
  const fs::path d = temp_dir("cli_midrun");
  const std::string counters = (d / "c.json").string();
  // Paced so the first row takes ~1.9 s; the save at its end finds its temp path taken.
  FILE* p = popen((std::string(LOOMCTL_PATH) +
                   " weave --rows 3 --no-telemetry --realtime --pace 4 --counters " + counters + " 2>&1")
                      .c_str(),
                  "r");
  // Once armed (its probe save wrote the file: a slow start, as under a sanitizer, must not meet the
  // obstacle before it), the save at row 1's end finds its temp path taken.
  for (int i = 0; i < 400 && !fs::exists(counters); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  fs::create_directories(d / "c.json.tmp");
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) out += buf;
  const int st = pclose(p);
  EXPECT_EQ(WIFEXITED(st) ? WEXITSTATUS(st) : -1, 3) << out;
  EXPECT_NE(out.find("FAULT counters_not_saved"), std::string::npos) << out;
  EXPECT_EQ(out.find("row 2/3"), std::string::npos) << "wove on after a failed save:\n" << out;
  EXPECT_EQ(slurp(counters), "{\"rows\":0,\"picks\":0,\"beats\":0,\"picks_in_row\":0}\n");  // the probe save
  fs::remove_all(d);
}
