// See production_record.hpp. SQLite's C API through a few small helpers: every statement prepared,
// bound and stepped, every failure a RecordError naming the file and SQLite's message.
#include "loom/record/production_record.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace loom::record {
namespace {

const char* const kStateNames[kMachineStates] = {
    "weaving", "knotting", "waiting_for_weaver", "paused", "faulted", "idle", "off"};

// Version 1, as the first loomctl with a record wrote it. A new file is made as version 1 and migrated,
// so a new record and an upgraded one have exactly the same shape.
constexpr const char* kSchemaV1 = R"sql(
CREATE TABLE schema_version (version INTEGER NOT NULL);
CREATE TABLE jobs (
  id INTEGER PRIMARY KEY,
  design_name TEXT NOT NULL,
  sha256 TEXT NOT NULL,
  length_rows INTEGER NOT NULL,
  started_ns INTEGER NOT NULL,
  ended_ns INTEGER,
  recorded_until_ns INTEGER NOT NULL
);
CREATE TABLE state_time (
  job_id INTEGER NOT NULL REFERENCES jobs(id),
  state TEXT NOT NULL,
  ns INTEGER NOT NULL,
  PRIMARY KEY (job_id, state)
);
CREATE TABLE rows (
  job_id INTEGER NOT NULL REFERENCES jobs(id),
  row INTEGER NOT NULL,
  ended_ns INTEGER NOT NULL,
  knots_by_heads INTEGER NOT NULL,
  knots_retried INTEGER NOT NULL,
  knots_by_hand INTEGER NOT NULL,
  PRIMARY KEY (job_id, row)
);
CREATE TABLE yarn (
  job_id INTEGER NOT NULL REFERENCES jobs(id),
  colour TEXT NOT NULL,
  knots INTEGER NOT NULL,
  PRIMARY KEY (job_id, colour)
);
CREATE TABLE faults (
  id INTEGER PRIMARY KEY,
  job_id INTEGER NOT NULL REFERENCES jobs(id),
  name TEXT NOT NULL,
  code INTEGER NOT NULL,
  at_ns INTEGER NOT NULL,
  cleared_ns INTEGER
);
)sql";

// Version 2: a job is woven again after `job start-over`, so the record keeps one entry per weaving.
// jobs.id becomes the record's own key of one weaving (every other table's job_id refers to it); the
// queue's job number moves to jobs.job, beside the weaving's number (1, 2, ...). A version-1 job was its
// first weaving, under the same key.
constexpr const char* kMigrateV1ToV2 = R"sql(
ALTER TABLE jobs ADD COLUMN job INTEGER NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN weaving INTEGER NOT NULL DEFAULT 1;
UPDATE jobs SET job = id;
CREATE UNIQUE INDEX jobs_by_weaving ON jobs (job, weaving);
UPDATE schema_version SET version = 2;
)sql";

// One prepared statement, finalized on scope exit.
class Stmt {
 public:
  Stmt(sqlite3* db, const std::string& path, const char* sql) : db_(db), path_(path) {
    if (sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) != SQLITE_OK) fail("prepare");
  }
  ~Stmt() { sqlite3_finalize(s_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  Stmt& bind(int i, std::int64_t v) {
    if (sqlite3_bind_int64(s_, i, v) != SQLITE_OK) fail("bind");
    return *this;
  }
  Stmt& bind(int i, const std::string& v) {
    if (sqlite3_bind_text(s_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT) != SQLITE_OK)
      fail("bind");
    return *this;
  }
  bool row() {  // true: a result row is ready; false: done
    const int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) fail("step");
    return false;
  }
  void run() {
    while (row()) {
    }
  }
  std::int64_t i64(int c) const { return sqlite3_column_int64(s_, c); }
  bool null(int c) const { return sqlite3_column_type(s_, c) == SQLITE_NULL; }
  std::string text(int c) const {
    const auto* t = sqlite3_column_text(s_, c);
    return t ? std::string(reinterpret_cast<const char*>(t),
                           static_cast<std::size_t>(sqlite3_column_bytes(s_, c)))
             : "";
  }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw RecordError(path_ + ": production record: SQLite " + what + " failed: " + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  const std::string& path_;
  sqlite3_stmt* s_ = nullptr;
};

void exec_on(sqlite3* db, const std::string& path, const char* sql) {
  char* err = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string why = err ? err : sqlite3_errmsg(db);
    sqlite3_free(err);
    throw RecordError(path + ": production record: " + why);
  }
}

// The schema's version, checked; 0 when the database has no tables at all (a new file).
int schema_version(sqlite3* db, const std::string& path) {
  std::int64_t tables = 0;
  {
    Stmt s(db, path, "SELECT count(*) FROM sqlite_master WHERE type = 'table'");
    if (s.row()) tables = s.i64(0);
  }
  if (tables == 0) return 0;
  Stmt has(db, path, "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = 'schema_version'");
  if (!has.row() || has.i64(0) != 1) {
    throw RecordError(
        path + ": not a loomctl production record (an SQLite database without a schema_version table)");
  }
  Stmt v(db, path, "SELECT version FROM schema_version");
  std::vector<std::int64_t> versions;
  while (v.row()) versions.push_back(v.i64(0));
  if (versions.size() != 1) {
    throw RecordError(path + ": production record's schema_version has " + std::to_string(versions.size()) +
                      " rows, want 1 (refusing to touch it)");
  }
  if (versions[0] < 1 || versions[0] > ProductionRecord::kSchemaVersion) {
    throw RecordError(path + ": production record of schema version " + std::to_string(versions[0]) +
                      "; this loomctl reads versions 1.." + std::to_string(ProductionRecord::kSchemaVersion) +
                      " and writes version " + std::to_string(ProductionRecord::kSchemaVersion) +
                      " (refusing to touch it)");
  }
  return static_cast<int>(versions[0]);
}

sqlite3* open_db(const std::string& path, int flags) {
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &db, flags | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    const std::string why = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    sqlite3_close(db);
    throw RecordError(path + ": cannot open the production record: " + why);
  }
  return db;
}

// A file that is not an SQLite database shows first as SQLITE_NOTADB on the first statement: said plainly.
int checked_version(sqlite3* db, const std::string& path) {
  try {
    return schema_version(db, path);
  } catch (const RecordError&) {
    if (sqlite3_errcode(db) == SQLITE_NOTADB) {
      throw RecordError(path +
                        ": not a loomctl production record (not an SQLite database; refusing to touch it)");
    }
    throw;
  }
}

}  // namespace

const char* machine_state_name(MachineState s) {
  return kStateNames[static_cast<int>(s)];
}

const char* opcua_machinery_state(MachineState s) {
  switch (s) {
    case MachineState::kWeaving:
    case MachineState::kKnotting:
      return "Executing";
    case MachineState::kWaitingForWeaver:
    case MachineState::kPaused:
    case MachineState::kIdle:
      return "NotExecuting";
    case MachineState::kFaulted:
      return "OutOfService";
    case MachineState::kOff:
      return "NotAvailable";
  }
  return "NotAvailable";
}

ProductionRecord::ProductionRecord(const std::string& path) : path_(path) {
  // One writer: a second one (another process, or a second object here) is refused at once. SQLite's own
  // locks would only serialise the two, row by row, into one muddled record. The lock is a flock on a file
  // beside the database, released by the kernel when the writer dies.
  writer_lock_ = ::open((path + ".writer").c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (writer_lock_ < 0) {
    throw RecordError(path +
                      ".writer: cannot open the production record's writer lock: " + std::strerror(errno));
  }
  if (::flock(writer_lock_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(writer_lock_);
    const std::string why = err == EWOULDBLOCK ? "lock " + path + ".writer held" : std::strerror(err);
    throw RecordError(path + ": the production record has a writer already (" + why +
                      "): one loomctl writes it");
  }
  // A file that exists but is not an SQLite database must not be turned into one.
  db_ = open_db(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  try {
    sqlite3_busy_timeout(db_, 0);  // one writer: a second one is refused at once, not queued
    const int version = checked_version(db_, path_);
    exec("PRAGMA journal_mode = WAL");
    exec("PRAGMA synchronous = FULL");
    exec("PRAGMA foreign_keys = ON");
    if (version < kSchemaVersion) {  // a new file, or an older loomctl's record: one transaction
      exec("BEGIN IMMEDIATE");
      if (version == 0) {
        exec(kSchemaV1);
        exec("INSERT INTO schema_version (version) VALUES (1)");
      }
      exec(kMigrateV1ToV2);
      exec("COMMIT");
    }
    Stmt wal(db_, path_, "PRAGMA journal_mode");
    if (!wal.row() || wal.text(0) != "wal")
      throw RecordError(path_ + ": production record: SQLite refused WAL mode");
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    ::close(writer_lock_);
    throw;
  }
}

ProductionRecord::~ProductionRecord() {
  sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);  // an uncommitted transaction after a throw
  sqlite3_close(db_);
  ::close(writer_lock_);  // releases the flock
}

void ProductionRecord::exec(const char* sql) {
  exec_on(db_, path_, sql);
}

std::string ProductionRecord::weaving_name(std::uint32_t job, std::uint32_t weaving) {
  return "job " + std::to_string(job) + (weaving > 1 ? " (weaving " + std::to_string(weaving) + ")" : "");
}

void ProductionRecord::need_job(const char* what) const {
  if (job_ == 0) throw RecordError(path_ + ": no job begun to " + what);
}

void ProductionRecord::credit(WallNs at) {
  if (at < since_) {
    throw RecordError(path_ + ": " + job_name_ + ": time went back from " + std::to_string(since_) +
                      " ns to " + std::to_string(at) +
                      " ns (the record's instants come from the tick count)");
  }
  pending_[static_cast<std::size_t>(state_)] += at - since_;
  since_ = at;
}

void ProductionRecord::flush(WallNs at) {
  credit(at);
  for (int s = 0; s < kMachineStates; ++s) {
    if (pending_[static_cast<std::size_t>(s)] == 0) continue;
    Stmt(db_, path_, "UPDATE state_time SET ns = ns + ? WHERE job_id = ? AND state = ?")
        .bind(1, pending_[static_cast<std::size_t>(s)])
        .bind(2, job_)
        .bind(3, kStateNames[s])
        .run();
  }
  Stmt(db_, path_, "UPDATE jobs SET recorded_until_ns = ? WHERE id = ?").bind(1, at).bind(2, job_).run();
}

// A transaction that is rolled back, and the in-memory time restored, unless committed: a failed write
// leaves the record and this writer as before the call.
namespace {
struct Txn {
  sqlite3* db;
  const std::string& path;
  std::array<std::int64_t, kMachineStates>& pending;
  WallNs& since;
  std::array<std::int64_t, kMachineStates> saved_pending;
  WallNs saved_since;
  bool done = false;
  Txn(sqlite3* d, const std::string& p, std::array<std::int64_t, kMachineStates>& pend, WallNs& s)
      : db(d), path(p), pending(pend), since(s), saved_pending(pend), saved_since(s) {
    exec_on(db, path, "BEGIN IMMEDIATE");
  }
  void commit() {
    exec_on(db, path, "COMMIT");
    pending.fill(0);
    done = true;
  }
  ~Txn() {
    if (done) return;
    sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
    pending = saved_pending;
    since = saved_since;
  }
};
}  // namespace

void ProductionRecord::begin_job(const JobInfo& job, MachineState s, WallNs at) {
  if (job.id == 0) throw RecordError(path_ + ": job 0: job numbers start at 1");
  if (job.weaving == 0)
    throw RecordError(path_ + ": job " + std::to_string(job.id) + ": weavings start at 1");
  const std::string name = weaving_name(job.id, job.weaving);
  std::array<std::int64_t, kMachineStates> pending{};
  WallNs since = at;
  Txn t(db_, path_, pending, since);
  {
    // The job's number names one design for ever (the queue never reuses it), whichever weaving.
    Stmt other(db_, path_, "SELECT sha256, max(weaving) FROM jobs WHERE job = ?");
    other.bind(1, job.id);
    if (other.row() && !other.null(0)) {
      if (other.text(0) != job.sha256) {
        throw RecordError(path_ + ": job " + std::to_string(job.id) + " is recorded with design hash " +
                          other.text(0) + ", not " + job.sha256 + " (another queue's job?)");
      }
      if (other.i64(1) > job.weaving) {
        throw RecordError(path_ + ": " + name + " begun, but weaving " + std::to_string(other.i64(1)) +
                          " is recorded already (an older job queue?)");
      }
    }
  }
  std::int64_t key = 0;
  Stmt q(db_, path_, "SELECT id, ended_ns, recorded_until_ns FROM jobs WHERE job = ? AND weaving = ?");
  q.bind(1, job.id).bind(2, job.weaving);
  if (q.row()) {
    key = q.i64(0);
    if (!q.null(1)) {
      throw RecordError(path_ + ": " + name +
                        " is recorded as ended (its carpet was cut off: `job start-over` weaves it again)");
    }
    const WallNs until = q.i64(2);
    if (at < until) {
      throw RecordError(path_ + ": " + name + " resumed at " + std::to_string(at) +
                        " ns, before its last record at " + std::to_string(until) + " ns");
    }
    // The gap since the last commit: nobody ran the job (power off, service stopped, or rows lost with
    // the power — their time is kept as off, never invented as weaving).
    Stmt(db_, path_, "UPDATE state_time SET ns = ns + ? WHERE job_id = ? AND state = 'off'")
        .bind(1, at - until)
        .bind(2, key)
        .run();
    Stmt(db_, path_, "UPDATE jobs SET recorded_until_ns = ? WHERE id = ?").bind(1, at).bind(2, key).run();
  } else {
    Stmt(db_, path_,
         "INSERT INTO jobs (job, weaving, design_name, sha256, length_rows, started_ns, recorded_until_ns) "
         "VALUES (?, ?, ?, ?, ?, ?, ?)")
        .bind(1, job.id)
        .bind(2, job.weaving)
        .bind(3, job.design_name)
        .bind(4, job.sha256)
        .bind(5, static_cast<std::int64_t>(job.length_rows))
        .bind(6, at)
        .bind(7, at)
        .run();
    key = sqlite3_last_insert_rowid(db_);
    for (const char* state : kStateNames) {
      Stmt(db_, path_, "INSERT INTO state_time (job_id, state, ns) VALUES (?, ?, 0)")
          .bind(1, key)
          .bind(2, state)
          .run();
    }
  }
  t.commit();
  job_ = key;
  job_name_ = name;
  state_ = s;
  since_ = at;
  pending_.fill(0);
}

void ProductionRecord::set_state(MachineState s, WallNs at) {
  need_job("set a state of");
  credit(at);
  state_ = s;
}

void ProductionRecord::fault(const std::string& name, int code, WallNs at) {
  need_job("record a fault of");
  Txn t(db_, path_, pending_, since_);
  flush(at);
  Stmt(db_, path_, "INSERT INTO faults (job_id, name, code, at_ns) VALUES (?, ?, ?, ?)")
      .bind(1, job_)
      .bind(2, name)
      .bind(3, code)
      .bind(4, at)
      .run();
  t.commit();
}

void ProductionRecord::fault_cleared(WallNs at) {
  need_job("clear a fault of");
  Txn t(db_, path_, pending_, since_);
  flush(at);
  Stmt(db_, path_, "UPDATE faults SET cleared_ns = ? WHERE job_id = ? AND cleared_ns IS NULL")
      .bind(1, at)
      .bind(2, job_)
      .run();
  t.commit();
}

void ProductionRecord::row_done(const RowDone& r, WallNs at) {
  need_job("record a row of");
  Txn t(db_, path_, pending_, since_);
  flush(at);
  {
    Stmt dup(db_, path_, "SELECT count(*) FROM rows WHERE job_id = ? AND row = ?");
    dup.bind(1, job_).bind(2, static_cast<std::int64_t>(r.row));
    if (dup.row() && dup.i64(0) != 0) {
      throw RecordError(path_ + ": row " + std::to_string(r.row) + " of " + job_name_ +
                        " is recorded already (a row is woven once)");
    }
  }
  Stmt(db_, path_,
       "INSERT INTO rows (job_id, row, ended_ns, knots_by_heads, knots_retried, knots_by_hand) VALUES (?, ?, "
       "?, ?, ?, ?)")
      .bind(1, job_)
      .bind(2, static_cast<std::int64_t>(r.row))
      .bind(3, at)
      .bind(4, r.knots_by_heads)
      .bind(5, r.knots_retried)
      .bind(6, r.knots_by_hand)
      .run();
  for (const auto& [colour, knots] : r.yarn) {
    Stmt(db_, path_,
         "INSERT INTO yarn (job_id, colour, knots) VALUES (?, ?, ?) "
         "ON CONFLICT (job_id, colour) DO UPDATE SET knots = knots + excluded.knots")
        .bind(1, job_)
        .bind(2, colour)
        .bind(3, knots)
        .run();
  }
  t.commit();
}

void ProductionRecord::commit(WallNs at) {
  need_job("commit the time of");
  Txn t(db_, path_, pending_, since_);
  flush(at);
  t.commit();
}

void ProductionRecord::end_job(WallNs at) {
  need_job("end");
  Txn t(db_, path_, pending_, since_);
  flush(at);
  Stmt(db_, path_, "UPDATE jobs SET ended_ns = ? WHERE id = ?").bind(1, at).bind(2, job_).run();
  t.commit();
  job_ = 0;
}

namespace {
// A read-only connection beside the writer (which may be running), closed on scope exit.
struct Reader {
  sqlite3* db;
  explicit Reader(const std::string& path) : db(open_db(path, SQLITE_OPEN_READONLY)) {
    sqlite3_busy_timeout(db, 2000);  // the writer's commit is short
  }
  ~Reader() { sqlite3_close(db); }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;
};
}  // namespace

std::optional<JobReport> read_job_report(const std::string& path, std::uint32_t id, std::uint32_t weaving) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw RecordError(path + ": no production record (nothing was woven with this state directory yet)");
  }
  const Reader reader(path);
  sqlite3* db = reader.db;
  const int version = checked_version(db, path);
  exec_on(db, path, "BEGIN");  // one snapshot for every query below
  JobReport r;
  std::int64_t key = 0;
  {
    // Read-only: a version-1 record (not yet opened by this loomctl's writer) is read as it is, each of
    // its jobs the first weaving.
    const char* sql =
        version == 1
            ? "SELECT id, 1, design_name, sha256, length_rows, started_ns, ended_ns, recorded_until_ns, 1 "
              "FROM "
              "jobs WHERE id = ?1 AND ?2 IN (0, 1)"
            : "SELECT id, weaving, design_name, sha256, length_rows, started_ns, ended_ns, "
              "recorded_until_ns, "
              "(SELECT max(weaving) FROM jobs WHERE job = ?1) FROM jobs WHERE job = ?1 AND weaving = "
              "(CASE ?2 WHEN 0 THEN (SELECT max(weaving) FROM jobs WHERE job = ?1) ELSE ?2 END)";
    Stmt q(db, path, sql);
    q.bind(1, id).bind(2, weaving);
    if (!q.row()) return std::nullopt;
    key = q.i64(0);
    r.id = id;
    r.weaving = static_cast<std::uint32_t>(q.i64(1));
    r.design_name = q.text(2);
    r.sha256 = q.text(3);
    r.length_rows = static_cast<std::uint64_t>(q.i64(4));
    r.started = q.i64(5);
    if (!q.null(6)) r.ended = q.i64(6);
    r.recorded_until = q.i64(7);
    r.weavings = static_cast<std::uint32_t>(q.i64(8));
  }
  {
    Stmt q(db, path, "SELECT state, ns FROM state_time WHERE job_id = ?");
    q.bind(1, key);
    while (q.row()) {
      const std::string name = q.text(0);
      for (int s = 0; s < kMachineStates; ++s) {
        if (name == kStateNames[s]) r.state_ns[static_cast<std::size_t>(s)] = q.i64(1);
      }
    }
  }
  {
    Stmt q(db, path,
           "SELECT count(*), coalesce(max(row), 0), coalesce(sum(knots_by_heads), 0), "
           "coalesce(sum(knots_retried), 0), "
           "coalesce(sum(knots_by_hand), 0) FROM rows WHERE job_id = ?");
    q.bind(1, key);
    if (q.row()) {
      r.rows = static_cast<std::uint64_t>(q.i64(0));
      r.last_row = static_cast<std::uint64_t>(q.i64(1));
      r.knots_by_heads = static_cast<std::uint64_t>(q.i64(2));
      r.knots_retried = static_cast<std::uint64_t>(q.i64(3));
      r.knots_by_hand = static_cast<std::uint64_t>(q.i64(4));
    }
  }
  {
    Stmt q(db, path, "SELECT colour, knots FROM yarn WHERE job_id = ? ORDER BY colour");
    q.bind(1, key);
    while (q.row()) r.yarn[q.text(0)] = static_cast<std::uint64_t>(q.i64(1));
  }
  {
    Stmt q(db, path, "SELECT at_ns, name, code, cleared_ns FROM faults WHERE job_id = ? ORDER BY id");
    q.bind(1, key);
    while (q.row()) {
      FaultRecord f{q.i64(0), q.text(1), static_cast<int>(q.i64(2)), std::nullopt};
      if (!q.null(3)) f.cleared = q.i64(3);
      r.faults.push_back(f);
    }
  }
  exec_on(db, path, "COMMIT");
  return r;
}

std::optional<WallNs> read_latest_instant(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  const Reader reader(path);
  sqlite3* db = reader.db;
  if (checked_version(db, path) == 0) return std::nullopt;
  Stmt q(db, path, "SELECT max(recorded_until_ns) FROM jobs");
  if (!q.row() || q.null(0)) return std::nullopt;
  return q.i64(0);
}

}  // namespace loom::record
