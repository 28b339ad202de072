// The production record in SQLite: the states' times add up to the job's wall time through restarts
// (checked against the test's own tally of the intervals it gave), a child killed mid-write leaves the
// last committed row intact, a database of another schema version or not a database is refused and left
// as it was, and `loomctl report job N` prints the record as text, CSV and JSON.
#include "loom/record/production_record.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "cli_run.hpp"
#include "loom/record/report_format.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;
using namespace loom::record;

namespace {

using loom::test::read_text_file;

struct TempDir {
  fs::path dir;
  TempDir() {
    char tmpl[] = "/tmp/loom_record_test.XXXXXX";
    dir = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(dir); }
  std::string db() const { return ProductionRecord::path_in(dir.string()); }
};

unsigned test_seed() {
  const char* env = std::getenv("LOOM_TEST_SEED");
  const unsigned seed =
      env != nullptr ? static_cast<unsigned>(std::strtoul(env, nullptr, 10)) : std::random_device{}();
  std::printf("seed %u (LOOM_TEST_SEED replays)\n", seed);
  return seed;
}

const JobInfo kJob{3, 1, "knot_demo.csv", std::string(64, 'a'), 540};
constexpr WallNs kT0 = 1'796'000'000'000'000'000;  // 2026-11-30

template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const RecordError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(ProductionRecord, StatesAddUpToTheWallTimeThroughRestarts) {
  TempDir t;
  std::mt19937_64 rng(test_seed());
  std::array<std::int64_t, kMachineStates> tally{};
  WallNs now = kT0;
  std::uint64_t row = 0, heads = 0, retried = 0, by_hand = 0, faults = 0;
  std::map<std::string, std::uint64_t> yarn;
  for (int run = 0; run < 4; ++run) {
    ProductionRecord rec(t.db());
    if (run > 0) {
      const WallNs off = static_cast<WallNs>(rng() % 50'000'000'000ull);  // the power was off this long
      tally[static_cast<std::size_t>(MachineState::kOff)] += off;
      now += off;
    }
    auto state = static_cast<MachineState>(rng() % 6);
    rec.begin_job(kJob, state, now);
    for (int step = 0; step < 200; ++step) {
      const WallNs dt = static_cast<WallNs>(rng() % 3'000'000'000ull);  // up to 3 s
      tally[static_cast<std::size_t>(state)] += dt;
      now += dt;
      switch (rng() % 4) {
        case 0: {
          RowDone r{++row,
                    static_cast<std::uint32_t>(rng() % 360),
                    static_cast<std::uint32_t>(rng() % 5),
                    static_cast<std::uint32_t>(rng() % 3),
                    {{"R", 300}, {"I", static_cast<std::uint32_t>(rng() % 60)}}};
          heads += r.knots_by_heads;
          retried += r.knots_retried;
          by_hand += r.knots_by_hand;
          for (const auto& [c, k] : r.yarn) yarn[c] += k;
          rec.row_done(r, now);
          break;
        }
        case 1:
          if (rng() % 10 == 0) {
            rec.fault("knot_servo_lag", 41, now);
            ++faults;
          } else {
            rec.fault_cleared(now);
          }
          break;
        default:
          state = static_cast<MachineState>(rng() % 6);
          rec.set_state(state, now);
      }
    }
    rec.commit(now);
  }
  const auto r = read_job_report(t.db(), kJob.id);
  ASSERT_TRUE(r.has_value());
  std::int64_t sum = 0;
  for (int s = 0; s < kMachineStates; ++s) {
    EXPECT_EQ(r->state_ns[static_cast<std::size_t>(s)], tally[static_cast<std::size_t>(s)])
        << machine_state_name(static_cast<MachineState>(s));
    sum += r->state_ns[static_cast<std::size_t>(s)];
  }
  EXPECT_EQ(sum, r->wall_ns());
  EXPECT_EQ(r->wall_ns(), now - kT0);
  EXPECT_EQ(r->rows, row);
  EXPECT_EQ(r->last_row, row);
  EXPECT_EQ(r->knots_by_heads, heads);
  EXPECT_EQ(r->knots_retried, retried);
  EXPECT_EQ(r->knots_by_hand, by_hand);
  EXPECT_EQ(r->yarn, yarn);
  EXPECT_EQ(r->faults.size(), faults);
  EXPECT_FALSE(r->ended.has_value());
}

TEST(ProductionRecord, EndedJobAndItsRefusals) {
  TempDir t;
  ProductionRecord rec(t.db());
  EXPECT_NE(error_of([&] { rec.row_done({1, 0, 0, 0, {}}, kT0); }).find("no job begun"), std::string::npos);
  rec.begin_job(kJob, MachineState::kKnotting, kT0);
  rec.fault("estop", 7, kT0 + 1'000'000'000);
  rec.set_state(MachineState::kFaulted, kT0 + 1'000'000'000);
  rec.fault_cleared(kT0 + 4'500'000'000);
  rec.set_state(MachineState::kWeaving, kT0 + 4'500'000'000);
  rec.row_done({1, 360, 2, 1, {{"R", 363}}}, kT0 + 5'000'000'000);
  EXPECT_NE(error_of([&] {
              rec.row_done({1, 0, 0, 0, {}}, kT0 + 6'000'000'000);
            }).find("row 1 of job 3 is recorded already"),
            std::string::npos);
  EXPECT_NE(error_of([&] { rec.set_state(MachineState::kIdle, kT0); }).find("time went back"),
            std::string::npos);
  JobInfo other = kJob;
  other.sha256 = std::string(64, 'b');
  EXPECT_NE(
      error_of([&] { rec.begin_job(other, MachineState::kIdle, kT0 + 7'000'000'000); }).find("design hash"),
      std::string::npos);
  rec.end_job(kT0 + 8'000'000'000);
  EXPECT_FALSE(rec.job_open());
  EXPECT_NE(error_of([&] {
              rec.begin_job(kJob, MachineState::kIdle, kT0 + 9'000'000'000);
            }).find("recorded as ended"),
            std::string::npos);
  const auto r = read_job_report(t.db(), kJob.id);
  ASSERT_TRUE(r.has_value());
  ASSERT_TRUE(r->ended.has_value());
  EXPECT_EQ(r->wall_ns(), 8'000'000'000);
  EXPECT_EQ(r->state_ns[static_cast<std::size_t>(MachineState::kKnotting)], 1'000'000'000);
  EXPECT_EQ(r->state_ns[static_cast<std::size_t>(MachineState::kFaulted)], 3'500'000'000);
  EXPECT_EQ(r->state_ns[static_cast<std::size_t>(MachineState::kWeaving)],
            3'500'000'000);  // the refused row's time too
  ASSERT_EQ(r->faults.size(), 1u);
  EXPECT_EQ(*r->faults[0].cleared - r->faults[0].at, 3'500'000'000);
  EXPECT_FALSE(read_job_report(t.db(), 4).has_value());
}

// `job start-over` of a job the loom began weaves it again as its next weaving: a record of its own, from
// row 1, beside the first (kept as it was); the first is never reopened.
TEST(ProductionRecord, AJobStartedOverIsRecordedAsItsNextWeaving) {
  TempDir t;
  ProductionRecord rec(t.db());
  rec.begin_job(kJob, MachineState::kKnotting, kT0);
  rec.row_done({1, 360, 0, 0, {{"R", 360}}}, kT0 + 50'000'000'000);
  rec.row_done({2, 359, 1, 1, {{"R", 361}}}, kT0 + 100'000'000'000);
  rec.commit(kT0 + 110'000'000'000);  // stopped; then started over, not ended
  JobInfo second = kJob;
  second.weaving = 2;
  rec.begin_job(second, MachineState::kIdle, kT0 + 200'000'000'000);
  rec.set_state(MachineState::kWeaving, kT0 + 210'000'000'000);
  rec.row_done({1, 360, 0, 0, {{"R", 360}}}, kT0 + 260'000'000'000);  // row 1 again: another weaving's
  EXPECT_NE(error_of([&] {
              rec.row_done({1, 0, 0, 0, {}}, kT0 + 270'000'000'000);
            }).find("row 1 of job 3 (weaving 2) is recorded already"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              rec.begin_job(kJob, MachineState::kIdle, kT0 + 300'000'000'000);
            }).find("job 3 begun, but weaving 2 is recorded already"),
            std::string::npos);
  JobInfo other = second;
  other.weaving = 3;
  other.sha256 = std::string(64, 'b');
  EXPECT_NE(
      error_of([&] { rec.begin_job(other, MachineState::kIdle, kT0 + 300'000'000'000); }).find("design hash"),
      std::string::npos);

  const auto latest = read_job_report(t.db(), kJob.id);
  ASSERT_TRUE(latest.has_value());
  EXPECT_EQ(latest->weaving, 2u);
  EXPECT_EQ(latest->weavings, 2u);
  EXPECT_EQ(latest->rows, 1u);
  EXPECT_EQ(latest->started, kT0 + 200'000'000'000);
  EXPECT_EQ(latest->yarn.at("R"), 360u);
  EXPECT_EQ(latest->state_ns[static_cast<std::size_t>(MachineState::kIdle)], 10'000'000'000);
  const auto first = read_job_report(t.db(), kJob.id, 1);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->weaving, 1u);
  EXPECT_EQ(first->rows, 2u);
  EXPECT_EQ(first->knots_by_heads, 719u);
  EXPECT_EQ(first->yarn.at("R"), 721u);
  EXPECT_EQ(first->wall_ns(), 110'000'000'000);  // as it was left: the second weaving's time is its own
  EXPECT_FALSE(first->ended.has_value());
  EXPECT_NE(report_text(*first).find("weaving   1 of 2"), std::string::npos) << report_text(*first);
  EXPECT_NE(report_text(*first).find("(started over before its end)"), std::string::npos);
  EXPECT_FALSE(read_job_report(t.db(), kJob.id, 3).has_value());
}

// A record written by the loomctl before weavings (schema version 1) is read as it is, read-only and
// untouched, each job its first weaving; its writer's next open migrates it in place, keeping every figure.
TEST(ProductionRecord, AVersionOneRecordIsReadAndThenMigrated) {
  TempDir t;
  {
    // The version-1 file as that loomctl made it (its schema, written out here as the fixture).
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(t.db().c_str(), &db), SQLITE_OK);
    const char* v1 = R"sql(
      CREATE TABLE schema_version (version INTEGER NOT NULL);
      CREATE TABLE jobs (id INTEGER PRIMARY KEY, design_name TEXT NOT NULL, sha256 TEXT NOT NULL,
        length_rows INTEGER NOT NULL, started_ns INTEGER NOT NULL, ended_ns INTEGER,
        recorded_until_ns INTEGER NOT NULL);
      CREATE TABLE state_time (job_id INTEGER NOT NULL REFERENCES jobs(id), state TEXT NOT NULL,
        ns INTEGER NOT NULL, PRIMARY KEY (job_id, state));
      CREATE TABLE rows (job_id INTEGER NOT NULL REFERENCES jobs(id), row INTEGER NOT NULL,
        ended_ns INTEGER NOT NULL, knots_by_heads INTEGER NOT NULL, knots_retried INTEGER NOT NULL,
        knots_by_hand INTEGER NOT NULL, PRIMARY KEY (job_id, row));
      CREATE TABLE yarn (job_id INTEGER NOT NULL REFERENCES jobs(id), colour TEXT NOT NULL,
        knots INTEGER NOT NULL, PRIMARY KEY (job_id, colour));
      CREATE TABLE faults (id INTEGER PRIMARY KEY, job_id INTEGER NOT NULL REFERENCES jobs(id),
        name TEXT NOT NULL, code INTEGER NOT NULL, at_ns INTEGER NOT NULL, cleared_ns INTEGER);
      INSERT INTO schema_version VALUES (1);
      INSERT INTO jobs VALUES (3, 'knot_demo.csv',
        'aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa',
        540, 1796000000000000000, NULL, 1796000090000000000);
      INSERT INTO state_time VALUES (3, 'weaving', 30000000000), (3, 'knotting', 60000000000),
        (3, 'waiting_for_weaver', 0), (3, 'paused', 0), (3, 'faulted', 0), (3, 'idle', 0), (3, 'off', 0);
      INSERT INTO rows VALUES (3, 1, 1796000090000000000, 358, 2, 2);
      INSERT INTO yarn VALUES (3, 'R', 362);
    )sql";
    ASSERT_EQ(sqlite3_exec(db, v1, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
    sqlite3_close(db);
  }
  const std::string before = read_text_file(t.db());
  const auto check = [&](const char* when) {
    const auto r = read_job_report(t.db(), 3);
    ASSERT_TRUE(r.has_value()) << when;
    EXPECT_EQ(r->weaving, 1u) << when;
    EXPECT_EQ(r->weavings, 1u) << when;
    EXPECT_EQ(r->rows, 1u) << when;
    EXPECT_EQ(r->knots_by_heads, 358u) << when;
    EXPECT_EQ(r->yarn.at("R"), 362u) << when;
    EXPECT_EQ(r->wall_ns(), 90'000'000'000) << when;
    EXPECT_EQ(r->state_ns[static_cast<std::size_t>(MachineState::kKnotting)], 60'000'000'000) << when;
    EXPECT_FALSE(read_job_report(t.db(), 3, 2).has_value()) << when;
  };
  check("version 1, read-only");
  EXPECT_EQ(read_text_file(t.db()), before);  // a reader never migrates
  {
    ProductionRecord rec(t.db());  // the writer migrates
    check("migrated");
    rec.begin_job(kJob, MachineState::kKnotting, kT0 + 100'000'000'000);  // resumes weaving 1
    rec.row_done({2, 360, 0, 0, {{"R", 360}}}, kT0 + 150'000'000'000);
    JobInfo second = kJob;
    second.weaving = 2;
    rec.begin_job(second, MachineState::kIdle, kT0 + 200'000'000'000);
    rec.row_done({1, 360, 0, 0, {{"R", 360}}}, kT0 + 250'000'000'000);
  }
  const auto first = read_job_report(t.db(), 3, 1);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->rows, 2u);
  EXPECT_EQ(first->state_ns[static_cast<std::size_t>(MachineState::kOff)], 10'000'000'000);
  EXPECT_EQ(read_job_report(t.db(), 3)->weaving, 2u);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(t.db().c_str(), &db), SQLITE_OK);
  sqlite3_stmt* q = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT version FROM schema_version", -1, &q, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(q), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(q, 0), ProductionRecord::kSchemaVersion);
  sqlite3_finalize(q);
  sqlite3_close(db);
}

// A child writes rows and says which it committed; it is killed at a random moment, mid-transaction or
// between; the record reopens with every row it reported (and no half row), its states adding up.
TEST(ProductionRecord, AKillMidWriteKeepsTheLastCommittedRow) {
  std::mt19937_64 rng(test_seed());
  for (int trial = 0; trial < 5; ++trial) {
    TempDir t;
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      close(fds[0]);
      ProductionRecord rec(t.db());
      rec.begin_job(kJob, MachineState::kKnotting, kT0);
      for (std::uint64_t row = 1;; ++row) {
        const WallNs at = kT0 + static_cast<WallNs>(row) * 57'000'000'000;
        rec.set_state(MachineState::kWeaving, at - 7'000'000'000);
        rec.row_done({row, 360, 1, 0, {{"R", 200}, {"B", 161}}}, at);
        rec.set_state(MachineState::kKnotting, at);
        if (write(fds[1], &row, sizeof row) != sizeof row) _exit(1);
      }
    }
    close(fds[1]);
    const std::uint64_t kill_after = 3 + rng() % 20;
    std::uint64_t last = 0;
    while (last < kill_after) {
      ASSERT_EQ(read(fds[0], &last, sizeof last), static_cast<ssize_t>(sizeof last));
    }
    usleep(static_cast<useconds_t>(rng() % 20000));  // into the next row's write, or not
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    std::uint64_t reported = last;
    while (read(fds[0], &last, sizeof last) == static_cast<ssize_t>(sizeof last)) reported = last;
    close(fds[0]);
    // Reopen as the writer (WAL recovery), then read.
    {
      ProductionRecord rec(t.db());
      rec.begin_job(kJob, MachineState::kIdle, kT0 + static_cast<WallNs>(reported + 100) * 57'000'000'000);
    }
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2(t.db().c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* s = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &s, nullptr), SQLITE_OK);
    ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
    EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(s, 0)), "ok");
    sqlite3_finalize(s);
    sqlite3_close(db);
    const auto r = read_job_report(t.db(), kJob.id);
    ASSERT_TRUE(r.has_value());
    EXPECT_GE(r->last_row, reported) << "trial " << trial << ": a committed row was lost";
    EXPECT_LE(r->last_row, reported + 1);  // at most the row whose report the kill cut off
    EXPECT_EQ(r->rows, r->last_row);       // rows 1..last, none half written
    EXPECT_EQ(r->knots_by_heads, 360 * r->rows);
    EXPECT_EQ(r->yarn.at("B"), 161 * r->rows);
    std::int64_t sum = 0;
    for (const auto ns : r->state_ns) sum += ns;
    EXPECT_EQ(sum, r->wall_ns());
    EXPECT_EQ(r->state_ns[static_cast<std::size_t>(MachineState::kWeaving)],
              7'000'000'000 * static_cast<std::int64_t>(r->rows));
    std::printf("trial %d: killed after row %llu reported; %llu rows recorded\n", trial,
                static_cast<unsigned long long>(reported), static_cast<unsigned long long>(r->rows));
  }
}

TEST(ProductionRecord, AnotherSchemaVersionOrNotADatabaseIsRefusedAndLeftAlone) {
  TempDir t;
  { ProductionRecord rec(t.db()); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(t.db().c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE schema_version SET version = 3", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  const std::string before = read_text_file(t.db());
  const std::string e = error_of([&] { ProductionRecord rec(t.db()); });
  EXPECT_NE(
      e.find("production record of schema version 3; this loomctl reads versions 1..2 and writes version 2"),
      std::string::npos)
      << e;
  EXPECT_NE(error_of([&] { read_job_report(t.db(), 1); }).find("schema version 3"), std::string::npos);
  EXPECT_EQ(read_text_file(t.db()), before);

  const std::string text = t.dir.string() + "/notes.sqlite";
  std::ofstream(text) << "these are not the droids\n" << std::string(2000, 'x');
  EXPECT_NE(error_of([&] { ProductionRecord rec(text); }).find("not an SQLite database"), std::string::npos);
  EXPECT_EQ(read_text_file(text).substr(0, 25), "these are not the droids\n");

  const std::string other = t.dir.string() + "/other.sqlite";
  ASSERT_EQ(sqlite3_open(other.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE t (x)", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  EXPECT_NE(error_of([&] { ProductionRecord rec(other); }).find("without a schema_version table"),
            std::string::npos);
}

TEST(ProductionRecord, HasOneWriter) {
  TempDir t;
  {
    ProductionRecord first(t.db());
    EXPECT_NE(error_of([&] { ProductionRecord second(t.db()); }).find("has a writer already"),
              std::string::npos);
    EXPECT_TRUE(read_job_report(t.db(), 1) == std::nullopt);  // readers are welcome
  }
  EXPECT_NO_THROW(ProductionRecord again(t.db()));  // released with the first
}

TEST(ProductionRecord, WritesInWalMode) {
  TempDir t;
  { ProductionRecord rec(t.db()); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(t.db().c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &s, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(s), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(s, 0)), "wal");  // persistent in the file
  sqlite3_finalize(s);
  sqlite3_close(db);
}

TEST(ProductionRecord, OpcUaMachineryMap) {
  EXPECT_STREQ(opcua_machinery_state(MachineState::kWeaving), "Executing");
  EXPECT_STREQ(opcua_machinery_state(MachineState::kKnotting), "Executing");
  EXPECT_STREQ(opcua_machinery_state(MachineState::kWaitingForWeaver), "NotExecuting");
  EXPECT_STREQ(opcua_machinery_state(MachineState::kPaused), "NotExecuting");
  EXPECT_STREQ(opcua_machinery_state(MachineState::kIdle), "NotExecuting");
  EXPECT_STREQ(opcua_machinery_state(MachineState::kFaulted), "OutOfService");
  EXPECT_STREQ(opcua_machinery_state(MachineState::kOff), "NotAvailable");
  EXPECT_EQ(iso_utc(0), "1970-01-01T00:00:00.000Z");
  EXPECT_EQ(iso_utc(951'782'400'123'000'000), "2000-02-29T00:00:00.123Z");  // a leap day
}

// `loomctl report job N`: the same record in the three formats; refusals exit 2.
TEST(ReportCli, TextCsvAndJson) {
  TempDir t;
  {
    ProductionRecord rec(t.db());
    rec.begin_job(kJob, MachineState::kKnotting, kT0);
    rec.set_state(MachineState::kWeaving, kT0 + 50'000'000'000);
    rec.row_done({1, 358, 3, 2, {{"R", 300}, {"I", 63}}}, kT0 + 57'000'000'000);
    rec.set_state(MachineState::kWaitingForWeaver, kT0 + 57'000'000'000);
    rec.fault("selector_jam", 12, kT0 + 60'000'000'000);
    rec.commit(kT0 + 61'000'000'000);
  }
  const std::string base = std::string(LOOMCTL_PATH) + " report job ";
  const std::string dir = " --state-dir " + t.dir.string();
  const auto json = loom::test::run_command(base + "3 --format json" + dir);
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const auto j = nlohmann::json::parse(json.output);
  EXPECT_EQ(j["job"], 3);
  EXPECT_EQ(j["design"], "knot_demo.csv");
  EXPECT_DOUBLE_EQ(j["wall_s"].get<double>(), 61.0);
  EXPECT_DOUBLE_EQ(j["states"]["knotting"]["s"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(j["states"]["weaving"]["s"].get<double>(), 7.0);
  EXPECT_DOUBLE_EQ(j["states"]["waiting_for_weaver"]["s"].get<double>(), 4.0);
  EXPECT_EQ(j["states"]["waiting_for_weaver"]["opcua_machinery_state"], "NotExecuting");
  EXPECT_EQ(j["knots"]["by_heads"], 358);
  EXPECT_EQ(j["knots"]["retried"], 3);
  EXPECT_EQ(j["knots"]["by_hand"], 2);
  EXPECT_EQ(j["yarn_knots"]["I"], 63);
  EXPECT_EQ(j["faults"][0]["name"], "selector_jam");
  EXPECT_TRUE(j["faults"][0]["acknowledged"].is_null());
  EXPECT_DOUBLE_EQ(j["faults"][0]["downtime_s"].get<double>(), 1.0);
  EXPECT_EQ(j["started"], "2026-11-30T00:53:20.000Z");

  const auto csv = loom::test::run_command(base + "3 --format csv" + dir);
  ASSERT_EQ(csv.exit_code, 0) << csv.output;
  EXPECT_EQ(csv.output.substr(0, 23), "item,name,value,detail\n");
  EXPECT_NE(csv.output.find("state_s,knotting,50.000000,Executing\n"), std::string::npos) << csv.output;
  EXPECT_NE(csv.output.find("knots,by_hand,2,\n"), std::string::npos);
  EXPECT_NE(
      csv.output.find("fault,selector_jam,1.000000,2026-11-30T00:54:20.000Z code 12 not acknowledged\n"),
      std::string::npos)
      << csv.output;

  const auto text = loom::test::run_command(base + "3" + dir);
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_NE(text.output.find("job 3: knot_demo.csv"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("knots     358 by the heads, 3 retried, 2 by hand"), std::string::npos)
      << text.output;

  const auto none = loom::test::run_command(base + "4" + dir);
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.output.find("job 4 has no production record"), std::string::npos) << none.output;
  const auto bad_format = loom::test::run_command(base + "3 --format xml" + dir);
  EXPECT_EQ(bad_format.exit_code, 2) << bad_format.output;
  const auto missing = loom::test::run_command(base + "3 --state-dir " + t.dir.string() + "/nowhere");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("no production record"), std::string::npos) << missing.output;
}
