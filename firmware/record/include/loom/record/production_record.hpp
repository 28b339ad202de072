// The production record: per carpet job, what the loom did and how long it took, in an embedded SQLite
// database in the state directory (production.sqlite). Non-RT: written by the reporter at row ends, read
// by `loomctl report job N` (and the panel) at any time.
//
// Durability: one writer (the one loomctl that holds the state directory), WAL journal, synchronous=FULL:
// a row is on disk when row_done() returns, and a power cut or kill leaves the record as at its last
// committed row. Time is kept by state change: every instant the caller gives credits the time since the
// previous one to the state the machine was in, so the states' times add up to the job's wall time by
// construction; after a restart the time the job was not being run (power off, service stopped) is
// credited to kOff. Instants must not go back (derive them from the tick count).
//
// The schema carries its version (table schema_version); a database of another version, or a file that
// is not a loomctl record, is refused (RecordError) and left untouched.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

struct sqlite3;

namespace loom::record {

class RecordError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The machine's states, as the record keeps time in them. Their map to the machine states of OPC UA for
// Machinery (OPC 40001-1, MachineryItemState):
//   kWeaving, kKnotting                  → Executing      (the machine makes the carpet)
//   kWaitingForWeaver, kPaused, kIdle    → NotExecuting   (ready, not producing: a hand tie or reload
//                                                          asked, paused by the operator, nothing to do)
//   kFaulted                             → OutOfService   (a fault stopped it until acknowledged)
//   kOff                                 → NotAvailable   (no loomctl ran the job: power off, stopped)
enum class MachineState : std::uint8_t {
  kWeaving,
  kKnotting,
  kWaitingForWeaver,
  kPaused,
  kFaulted,
  kIdle,
  kOff
};
inline constexpr int kMachineStates = 7;
const char* machine_state_name(MachineState s);  // "weaving", "knotting", "waiting_for_weaver", ...
const char* opcua_machinery_state(
    MachineState s);  // "Executing", "NotExecuting", "OutOfService", "NotAvailable"

// Nanoseconds since the Unix epoch on the caller's wall clock (on the loom: the wall clock at arming plus
// ticks × period, so it never goes back).
using WallNs = std::int64_t;

struct JobInfo {
  std::uint32_t id = 0;       // the job queue's number
  std::uint32_t weaving = 1;  // 1 the first time; each `job start-over` weaves the job again as the next
  std::string design_name;
  std::string sha256;
  std::uint64_t length_rows = 0;
};

struct RowDone {
  std::uint64_t row = 0;  // 1-based row of the job
  std::uint32_t knots_by_heads = 0, knots_retried = 0, knots_by_hand = 0;
  std::map<std::string, std::uint32_t>
      yarn;  // knots of yarn taken per colour code (a retry takes yarn again)
};

class ProductionRecord {
 public:
  static constexpr const char* kFileName = "production.sqlite";
  static std::string path_in(const std::string& state_dir) { return state_dir + "/" + kFileName; }
  static constexpr int kSchemaVersion = 2;

  // Opens `path` for writing, creating the schema in a new file and migrating an older version's (version 1:
  // no weavings) in one transaction. RecordError naming the path when it is not a loomctl record of a version
  // up to kSchemaVersion, another writer has it open (flock on PATH.writer), or SQLite refuses.
  explicit ProductionRecord(const std::string& path);
  ~ProductionRecord();
  ProductionRecord(const ProductionRecord&) = delete;
  ProductionRecord& operator=(const ProductionRecord&) = delete;

  // The job's weaving is woven from `at` in state `s`: a weaving new to the record starts at `at`; one
  // recorded before (a restart) has the time since its last commit credited to kOff. Committed. RecordError
  // when that weaving is recorded as ended, `at` is before its last commit, its id names another design, or
  // a later weaving of the job is recorded already.
  void begin_job(const JobInfo& job, MachineState s, WallNs at);
  // From `at` the machine is in `s` (kept in memory; committed with the next row, fault or commit).
  void set_state(MachineState s, WallNs at);
  // A fault at `at` (committed at once). Its downtime runs until fault_cleared().
  void fault(const std::string& name, int code, WallNs at);
  // Every open fault of the job was acknowledged at `at` (committed at once).
  void fault_cleared(WallNs at);
  // Row `r.row` ended at `at`: its knots, yarn and the states' time up to `at`, in one transaction, durable
  // when this returns. RecordError when the row is recorded already.
  void row_done(const RowDone& r, WallNs at);
  // The time up to `at` (e.g. before a clean stop), without a row.
  void commit(WallNs at);
  // The carpet is done at `at`: the time up to it and the job's end committed; no job is open after.
  void end_job(WallNs at);

  bool job_open() const { return job_ != 0; }

 private:
  void credit(WallNs at);  // the time since since_ to state_ (in memory)
  void flush(WallNs at);   // credit, then write the pending state times and the job's recorded_until
  void need_job(const char* what) const;
  void exec(const char* sql);
  static std::string weaving_name(std::uint32_t job, std::uint32_t weaving);  // "job 3", "job 3 (weaving 2)"

  std::string path_;
  int writer_lock_ = -1;  // flock on PATH.writer: one writer
  sqlite3* db_ = nullptr;
  std::int64_t job_ = 0;  // the record's key of the weaving begun (jobs.id); 0: none
  std::string job_name_;  // as messages name it
  MachineState state_ = MachineState::kIdle;
  WallNs since_ = 0;
  std::array<std::int64_t, kMachineStates> pending_{};
};

// What the record holds about one job (read-only; `loomctl report job N`).
struct FaultRecord {
  WallNs at = 0;
  std::string name;
  int code = 0;
  std::optional<WallNs> cleared;  // none: still open (downtime runs to the record's end)
};
struct JobReport {
  std::uint32_t id = 0;
  std::uint32_t weaving = 1;   // which weaving of the job this is
  std::uint32_t weavings = 1;  // how many the record holds (a weaving before the last was started over)
  std::string design_name, sha256;
  std::uint64_t length_rows = 0;
  WallNs started = 0;
  std::optional<WallNs> ended;
  WallNs recorded_until = 0;  // the last commit: the report's "now"
  std::array<std::int64_t, kMachineStates> state_ns{};
  std::uint64_t rows = 0;      // rows recorded
  std::uint64_t last_row = 0;  // the highest of them
  std::uint64_t knots_by_heads = 0, knots_retried = 0, knots_by_hand = 0;
  std::map<std::string, std::uint64_t> yarn;  // knots per colour
  std::vector<FaultRecord> faults;

  WallNs wall_ns() const { return (ended ? *ended : recorded_until) - started; }
};

// Reads weaving `weaving` of job `id` (0: its latest) from the record at `path`, opened read-only (the
// writer may be running). nullopt when the record has no such job or weaving; RecordError when the file is
// missing or not a loomctl record of a version this loomctl reads.
std::optional<JobReport> read_job_report(const std::string& path, std::uint32_t id,
                                         std::uint32_t weaving = 0);
// The latest instant the record at `path` holds, over every job and weaving (nullopt: no file, or no job
// yet). A simulated loom, whose instants run ahead of the wall clock, starts its next job after it.
std::optional<WallNs> read_latest_instant(const std::string& path);

}  // namespace loom::record
