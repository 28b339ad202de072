// The carpet job queue: SHA-256 against FIPS 180-2's published digests and coreutils' sha256sum (a peer
// that shares no code), identity by content, the refusals (file:line, field, value; nothing changed) and
// the job's life (start, rows, knot cycles, carpet_done, start-over, remove).
#include "loom/job/job_queue.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_run.hpp"
#include "loom/config/config.hpp"
#include "loom/job/design_hash.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;
using loom::job::Job;
using loom::job::JobError;
using loom::job::JobLength;
using loom::job::JobQueue;
using loom::job::JobState;

namespace {

using loom::test::read_text_file;

void write(const std::string& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// A throwaway state directory per test.
struct TempDir {
  fs::path dir;
  TempDir() {
    char tmpl[] = "/tmp/loom_job_test.XXXXXX";
    dir = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(dir); }
  std::string operator/(const std::string& name) const { return (dir / name).string(); }
};

const std::string kDemo = std::string(LOOM_SOURCE_DIR) + "/firmware/config/designs/knot_demo.csv";
const std::string kKnottingLoom = std::string(LOOM_SOURCE_DIR) + "/firmware/config/knotting_loom.toml";

const loom::firmware::LoomConfig& knotting_loom() {
  static const loom::firmware::LoomConfig c = loom::firmware::load_loom_config(kKnottingLoom);
  return c;
}

// A design `width` knots wide and `rows` high, every knot `code` (palette R, I, B, G, Y defined).
std::string design_csv(int width, int rows, const std::string& code, const std::string& last_row_code = "") {
  std::string s =
      "palette,R,#a52a2a\npalette,I,#f3ead6\npalette,B,#1f3a6e\npalette,G,#00ff00\npalette,Y,#ffff00\n";
  for (int r = 0; r < rows; ++r) {
    const std::string& c = (r == rows - 1 && !last_row_code.empty()) ? last_row_code : code;
    for (int k = 0; k < width; ++k) s += (k ? "," : "") + c;
    s += "\n";
  }
  return s;
}

template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const JobError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(DesignHash, MatchesFips180Vectors) {
  // FIPS 180-2, appendix B.1 and the empty message.
  EXPECT_EQ(loom::job::sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(loom::job::sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(loom::job::sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_TRUE(loom::job::is_sha256_hex(loom::job::sha256_hex("x")));
  EXPECT_FALSE(loom::job::is_sha256_hex("BA7816BF8F01CFEA414140DE5DAE2223B00361A396177A9CB410FF61F20015AD"));
}

TEST(JobQueue, AddKnowsTheDesignByItsContent) {
  TempDir t;
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  const Job& j = q.add(kDemo, knotting_loom(), {});
  const auto sum = loom::test::run_command("sha256sum " + kDemo);
  ASSERT_EQ(sum.exit_code, 0) << sum.output;
  EXPECT_EQ(j.sha256, sum.output.substr(0, 64));  // coreutils agrees
  EXPECT_EQ(j.id, 1u);
  EXPECT_EQ(j.state, JobState::kQueued);
  EXPECT_EQ(j.design_name, "knot_demo.csv");
  EXPECT_EQ(j.knots_per_row, 360);
  EXPECT_EQ(j.design_rows, 8);
  EXPECT_EQ(j.length_rows, 8u);  // the design once
  ASSERT_EQ(j.yarn.size(), 6u);  // the knotting loom's six heads
  EXPECT_EQ(j.yarn[5], (loom::job::HeadYarn{{"B", 2}, {"I", 1}, {"R", 0}}));
  // Read back from disk: the same job.
  const JobQueue again = JobQueue::load(q.path());
  ASSERT_EQ(again.jobs().size(), 1u);
  EXPECT_EQ(JobQueue::format(again.jobs(), 2), JobQueue::format(q.jobs(), 2));
}

TEST(JobQueue, SameFileNameOtherContentIsAnotherJob) {
  TempDir t;
  fs::create_directories(t.dir / "a");
  fs::create_directories(t.dir / "b");
  write(t / "a/mine.csv", design_csv(360, 4, "R"));
  write(t / "b/mine.csv", design_csv(360, 4, "R", "B"));
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  const std::string h1 = q.add(t / "a/mine.csv", knotting_loom(), {}).sha256;
  const std::string h2 = q.add(t / "b/mine.csv", knotting_loom(), {}).sha256;
  EXPECT_NE(h1, h2);
  EXPECT_EQ(q.jobs().size(), 2u);
  EXPECT_EQ(q.job(1).design_name, q.job(2).design_name);
}

TEST(JobQueue, ChangedDesignFileIsRefusedNamingBothHashes) {
  TempDir t;
  write(t / "rug.csv", design_csv(360, 4, "R"));
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  const Job j = q.add(t / "rug.csv", knotting_loom(), {});
  EXPECT_NO_THROW(JobQueue::check_design(j));
  write(t / "rug.csv", design_csv(360, 4, "I"));
  const std::string now = loom::job::sha256_hex(read_text_file(t / "rug.csv"));
  EXPECT_EQ(error_of([&] { JobQueue::check_design(j); }),
            "the design file changed under job 1: hash " + now + ", was " + j.sha256 + " (" +
                (t / "rug.csv") + "; add it as a new job to weave the new design)");
  fs::remove(t / "rug.csv");
  EXPECT_NE(error_of([&] { JobQueue::check_design(j); }).find("cannot be read"), std::string::npos);
}

TEST(JobQueue, AddRefusesEveryColourInNoSlotAtOnceAndTouchesNothing) {
  TempDir t;
  write(t / "green.csv", design_csv(360, 3, "G", "Y"));
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  q.add(kDemo, knotting_loom(), {});
  const std::string before = read_text_file(q.path());
  const std::string e = error_of([&] { q.add(t / "green.csv", knotting_loom(), {}); });
  EXPECT_NE(e.find("colours in no magazine slot: G (720 knots), Y (360 knots)"), std::string::npos) << e;
  EXPECT_NE(e.find("R in slot 0, I in slot 1, B in slot 2"), std::string::npos) << e;
  EXPECT_EQ(read_text_file(q.path()), before);
  EXPECT_EQ(q.jobs().size(), 1u);
}

TEST(JobQueue, AddRefusesADesignNotFittedToTheLoom) {
  TempDir t;
  write(t / "narrow.csv", design_csv(40, 20, "R"));
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  const std::string e = error_of([&] { q.add(t / "narrow.csv", knotting_loom(), {}); });
  EXPECT_NE(e.find("the design is 40 knots wide; the loom"), std::string::npos) << e;
  EXPECT_NE(e.find("ties 360 knots per row"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(q.path()));
}

TEST(JobQueue, LengthInRowsMetresOrRepeats) {
  using loom::job::length_in_rows;
  EXPECT_EQ(length_in_rows({}, 8, 30.0), 8u);
  EXPECT_EQ(length_in_rows({.rows = 540}, 8, 30.0), 540u);
  EXPECT_EQ(length_in_rows({.repeats = 3}, 8, 30.0), 24u);
  EXPECT_EQ(length_in_rows({.metres = 1.8}, 8, 30.0), 540u);  // 18 dm × 30 rows/dm
  EXPECT_EQ(length_in_rows({.metres = 0.01}, 8, 30.0), 3u);
  EXPECT_NE(error_of([] { length_in_rows({.rows = 5, .repeats = 2}, 8, 30.0); }).find("give one of them"),
            std::string::npos);
  EXPECT_NE(error_of([] { length_in_rows({.metres = 0.001}, 8, 30.0); }).find("is 0 rows"),
            std::string::npos);
}

TEST(JobQueue, AJobsLifeFromStartToCarpetDoneAndOverAgain) {
  TempDir t;
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  q.add(kDemo, knotting_loom(), {.repeats = 2});  // 16 rows
  q.add(kDemo, knotting_loom(), {});
  EXPECT_EQ(q.current(), nullptr);
  q.start(1, 100);  // the production counters stand at 100 rows
  ASSERT_NE(q.current(), nullptr);
  EXPECT_NE(error_of([&] { q.start(2, 100); }).find("job 1 is current"), std::string::npos);
  EXPECT_NE(error_of([&] { q.remove(1); }).find("is the current job"), std::string::npos);
  EXPECT_FALSE(q.advance(101));
  q.knot_progress(7, 6);
  EXPECT_EQ(JobQueue::load(q.path()).job(1).progress.cycles_started, 7u);
  // A power cut between the counters' save and the queue's: two rows credited at once.
  EXPECT_FALSE(q.advance(103));
  const Job& j = q.job(1);
  EXPECT_EQ(j.progress.rows_done, 3u);
  EXPECT_EQ(j.next_row(), 4u);
  EXPECT_EQ(j.progress.cycles_started, 0u);  // the next row has no cycles yet
  EXPECT_NE(error_of([&] { q.advance(102); }).find("never go back"), std::string::npos);
  EXPECT_NE(error_of([&] { q.mark_carpet_done(); }).find("13 rows left"), std::string::npos);
  EXPECT_NE(error_of([&] { q.advance(117); }).find("would pass its length of 16 rows"), std::string::npos);
  EXPECT_TRUE(q.advance(116));
  EXPECT_EQ(q.job(1).next_design_row(), 0);  // 16 rows = the design twice
  q.mark_carpet_done();
  EXPECT_EQ(q.current(), nullptr);
  EXPECT_EQ(JobQueue::load(q.path()).job(1).state, JobState::kCarpetDone);
  q.start(2, 116);
  q.advance(118);
  q.start_over(2);
  EXPECT_EQ(q.job(2).next_row(), 1u);
  EXPECT_EQ(q.job(2).state, JobState::kCurrent);
  EXPECT_EQ(q.job(2).weaving, 2u);  // the loom had begun it: its record keeps the first weaving apart
  q.start_over(1);
  EXPECT_EQ(q.job(1).state, JobState::kQueued);
  EXPECT_EQ(q.job(1).progress.rows_done, 0u);
  EXPECT_EQ(JobQueue::load(q.path()).job(1).weaving, 2u);
  q.start_over(1);  // queued, never begun since: only reset, no empty weaving
  EXPECT_EQ(q.job(1).weaving, 2u);
  q.remove(1);
  EXPECT_EQ(JobQueue::load(q.path()).job(1).state, JobState::kRemoved);
  EXPECT_NE(error_of([&] { q.start_over(1); }).find("is removed"), std::string::npos);
  EXPECT_NE(error_of([&] { q.job(9); }).find("no job 9"), std::string::npos);
  // Ids are never reused.
  EXPECT_EQ(q.add(kDemo, knotting_loom(), {}).id, 3u);
}

TEST(JobQueue, CheckYarnAtStartNamesAColourNoLongerLoaded) {
  TempDir t;
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  const Job j = q.add(kDemo, knotting_loom(), {});
  EXPECT_NO_THROW(JobQueue::check_yarn(j, knotting_loom()));
  loom::firmware::LoomConfig changed = knotting_loom();
  changed.knotting.slot_colours = {"R", "B", "Y"};
  const std::string e = error_of([&] { JobQueue::check_yarn(j, changed); });
  EXPECT_NE(e.find("colours in no magazine slot: I;"), std::string::npos) << e;
}

// Every kind of damage to a queue file: refused naming file:line, the field and its value.
TEST(JobQueue, ABadFileIsRefusedWithLineFieldAndValue) {
  TempDir t;
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  q.add(kDemo, knotting_loom(), {});
  const std::string good = read_text_file(q.path());
  struct Case {
    std::string from, to, want;
  };
  const std::vector<Case> cases = {
      {"knots_per_row = 360", "knots_per_row = 36O", ":10: field \"knots_per_row\" = \"36O\": want 1..4000"},
      {"knots_per_row = 360", "knots_per_row = 0360", "field \"knots_per_row\" = \"0360\""},
      {"state = queued", "state = weaving", ":6: field \"state\" = \"weaving\": want queued, current"},
      {"length_rows = 8", "length_rows = -8", ":12: field \"length_rows\" = \"-8\""},
      {"rows_done = 0", "rows_done = 9", ":20: field \"rows_done\" = \"9\": beyond length_rows = 8"},
      {"cycles_done = 0", "cycles_done = 1",
       ":22: field \"cycles_done\" = \"1\": exceeds cycles_started = 0"},
      {"yarn.2 = B:2 I:1 R:0", "yarn.2 = B:2 I:1 R:16",
       ":15: field \"yarn.2\" = \"B:2 I:1 R:16\": want CODE:SLOT"},
      {"yarn.2 = B:2 I:1 R:0", "yarn.3 = B:2 I:1 R:0", ":15: field \"yarn.3\": want yarn.1, yarn.2"},
      {"weaving = 1", "weaving = 0", ":13: field \"weaving\" = \"0\": want 1..4294967295"},
      {"weaving = 1\n", "", ":5: [job 1] lacks field \"weaving\""},
      {"format = loomctl-jobs 2", "format = loomctl-jobs 1",
       ":13: unknown field \"weaving\" in a \"loomctl-jobs 1\" queue"},
      {"sha256 = ", "sha256 = X", ":9: field \"sha256\""},
      {"format = loomctl-jobs 2", "format = loomctl-jobs 3", ":2: field \"format\" = \"loomctl-jobs 3\""},
      {"next_id = 2", "next_id = 1", "field \"next_id\" = \"1\": not beyond job 1"},
      {"at_counter_rows = 0", "at_counter_rows = 0\nbogus = 1", ":24: unknown field \"bogus\" in [job 1]"},
      {"at_counter_rows = 0", "at_counter_rows = 0\nrows_done = 0", ":24: field \"rows_done\" given twice"},
      {"design_rows = 8\n", "", ":5: [job 1] lacks field \"design_rows\""},
      {"[job 1]", "[job one]", ":5: \"[job one]\": want a stanza header [job N]"},
      {"design_path = /", "design_path = ", ":7: field \"design_path\""},
  };
  for (const Case& c : cases) {
    std::string bad = good;
    const auto at = bad.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    bad.replace(at, c.from.size(), c.to);
    write(q.path(), bad);
    const std::string e = error_of([&] { JobQueue::load(q.path()); });
    EXPECT_NE(e.find(q.path()), std::string::npos) << e;
    EXPECT_NE(e.find(c.want), std::string::npos) << "want: " << c.want << "\ngot:  " << e;
    EXPECT_EQ(read_text_file(q.path()), bad);  // refused, never rewritten
  }
  // Two current jobs.
  JobQueue two = JobQueue::load((write(q.path(), good), q.path()));
  two.add(kDemo, knotting_loom(), {});
  std::string s = read_text_file(q.path());
  for (std::size_t p = s.find("state = queued"); p != std::string::npos; p = s.find("state = queued")) {
    s.replace(p, 14, "state = current");
  }
  write(q.path(), s);
  EXPECT_NE(error_of([&] { JobQueue::load(q.path()); }).find("\"state\" = \"current\": job 1 is current too"),
            std::string::npos);
}

// A queue written by the loomctl before weavings (format 1, no `weaving`) is read as every job in its first
// weaving, and written back as format 2.
TEST(JobQueue, AFormatOneQueueReadsAsFirstWeavings) {
  TempDir t;
  JobQueue q = JobQueue::load(JobQueue::path_in(t.dir.string()));
  q.add(kDemo, knotting_loom(), {});
  std::string v1 = read_text_file(q.path());
  const auto at = v1.find("weaving = 1\n");
  ASSERT_NE(at, std::string::npos);
  v1.erase(at, 12);
  v1.replace(v1.find("loomctl-jobs 2"), 14, "loomctl-jobs 1");
  write(q.path(), v1);
  JobQueue old = JobQueue::load(q.path());
  EXPECT_EQ(old.job(1).weaving, 1u);
  old.start(1, 0);
  EXPECT_NE(read_text_file(q.path()).find("format = loomctl-jobs 2"), std::string::npos);
  EXPECT_NE(read_text_file(q.path()).find("weaving = 1\n"), std::string::npos);
}
