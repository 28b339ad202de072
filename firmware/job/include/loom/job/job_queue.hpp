// The carpet job queue: what the loom is to weave, kept in the state directory across restarts and power
// cuts. Non-RT: read when a session is armed and by `loomctl job`, written after a row's counters.
//
// A job is one carpet: a design known by its content (the SHA-256 of its file, never its name: two files
// called mine.csv with other knots are two jobs), fitted to the loom (knots per row = the loom's), a
// length in rows (default: the design once; a repeat count or metres at the loom's rows_per_dm), the yarn
// map (palette code → magazine slot, per head) and its progress — the rows woven and the knot cycles of
// the next row, as counters.json and design_book.json keep them for the production counts. Its state:
//   queued       added, not started (a job is started only at the machine, as every start is);
//   current      the one the loom weaves (at most one);
//   carpet_done  its last row is woven: cut the carpet off, tie the fringe warp, start the next job;
//   removed      taken out of the queue (kept, so a job's number is never reused).
//
// The file (jobs.txt) is text, a header and one [job N] stanza per job, `field = value` lines. Every field
// is checked on reading; a file that is not exactly what loomctl writes is refused (JobError naming
// file:line, the field and the value) and nothing is changed. Every change is checked first, then the
// whole queue is written atomically (write_file_durably): a power cut leaves the old queue or the new.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "loom/config/config.hpp"

namespace loom::job {

// A refused job file or operation (bad input: the CLI exits 2).
class JobError : public firmware::ConfigError {
 public:
  using ConfigError::ConfigError;
};

enum class JobState : std::uint8_t { kQueued, kCurrent, kCarpetDone, kRemoved };
const char* job_state_name(JobState s);  // "queued", "current", "carpet_done", "removed"

// Palette code → magazine slot (0-based) of one head, for the colours the design uses.
using HeadYarn = std::map<std::string, int>;

struct JobProgress {
  std::uint64_t rows_done = 0;  // rows of this carpet woven: the next row is rows_done + 1
  std::uint32_t cycles_started =
      0;                          // knot cycles of the next row started (counters.json's knot_cycles_started)
  std::uint32_t cycles_done = 0;  // and finished (knot_cycles_done)
  std::uint32_t at_counter_rows = 0;  // the production counters' rows when this progress was written
};

struct Job {
  std::uint32_t id = 0;  // 1, 2, ... in the order added; never reused
  JobState state = JobState::kQueued;
  std::string design_path;  // absolute, as added
  std::string design_name;  // the file's name (for people; the hash is the identity)
  std::string sha256;       // of the design file's bytes when added
  int knots_per_row = 0;    // the design's width = the loom's knots per row
  int design_rows = 0;      // the design's height
  std::uint64_t length_rows = 0;
  std::uint32_t weaving = 1;  // 1, then +1 at each `job start-over` of a job the loom began (the record keeps
                              // each weaving apart)
  std::vector<HeadYarn> yarn;  // head 1 first; empty on a loom without knotting heads
  JobProgress progress;

  std::uint64_t next_row() const { return progress.rows_done + 1; }  // 1-based row of the carpet
  // 0-based design row (bottom = 0) the next row ties: the design repeats when the carpet is longer.
  int next_design_row() const {
    return static_cast<int>(progress.rows_done % static_cast<std::uint64_t>(design_rows));
  }
  bool all_rows_woven() const { return progress.rows_done >= length_rows; }
};

// How long the carpet is: at most one of these (none: the design once, no repeat).
struct JobLength {
  std::uint64_t rows = 0;     // explicit rows
  double metres = 0.0;        // along the carpet, at the loom's rows_per_dm (rounded to the nearest row)
  std::uint32_t repeats = 0;  // the design this many times
};
// Rows of a carpet `length` long of a design `design_rows` high on a loom weaving `rows_per_dm`. JobError
// when more than one is given, or the result is not 1..4294967295 rows.
std::uint64_t length_in_rows(const JobLength& length, int design_rows, double rows_per_dm);

class JobQueue {
 public:
  static constexpr const char* kFileName = "jobs.txt";
  static std::string path_in(const std::string& state_dir) { return state_dir + "/" + kFileName; }

  // Reads `path` (absent: an empty queue). JobError on a bad file (file:line, field, value).
  static JobQueue load(const std::string& path);

  const std::string& path() const { return path_; }
  const std::vector<Job>& jobs() const { return jobs_; }  // every job ever added, by id
  const Job& job(std::uint32_t id) const;                 // JobError "no job N" when there is none
  const Job* current() const;                             // the job in state current, or null

  // Each operation checks, then writes the whole queue durably; a refusal (JobError) changes nothing, a
  // failed write (std::runtime_error naming the path and errno) leaves the old file.
  //
  // Add the design file at `design_path` as a queued job for the loom `loom` (its knots per row, rows_per_dm
  // and magazines). Refused, naming the value: a design that cannot be read or parsed, whose width is not
  // the loom's knots per row, or — on a loom with knotting heads — with colours in no magazine slot (every
  // such colour listed at once with its knot count).
  const Job& add(const std::string& design_path, const firmware::LoomConfig& loom, const JobLength& length);
  // Removed from the queue (kept as `removed`). Refused for the current job and for a removed one.
  void remove(std::uint32_t id);
  // Back to row 1: progress cleared; a carpet_done job is queued again; a job the loom began (current, done,
  // or with progress) gets its next weaving number, so the production record keeps the earlier weaving as it
  // was. Refused for a removed job.
  void start_over(std::uint32_t id);
  // At the machine: `id` (queued) becomes current, its progress based at production row `counter_rows`.
  // Refused when another job is current, or the job is not queued.
  const Job& start(std::uint32_t id, std::uint32_t counter_rows);
  // After a row's counters were saved: the current job has woven up to production row `counter_rows`
  // (rows since its last write are credited to it, as the design book does, so a power cut between the
  // two saves loses nothing) and the next row's knot cycles are zero. Returns true when every row of the
  // carpet is woven (the loop stops and calls mark_carpet_done). Refused: no current job, counters behind
  // the job's (production counts never go back), or rows beyond the carpet's length.
  bool advance(std::uint32_t counter_rows);
  // The next row's knot cycles (mirrors counters.json; the counters stay the authority within a row).
  void knot_progress(std::uint32_t cycles_started, std::uint32_t cycles_done);
  // The current job, all rows woven, ends in carpet_done. Refused when rows are left.
  void mark_carpet_done();

  // The design file still has the bytes the job was added with. JobError "the design file changed under
  // job N: hash X, was Y (PATH)" or that it cannot be read: never silently mixed.
  static void check_design(const Job& job);
  // The same check, returning the bytes it hashed (read once: what is woven is what was checked).
  static std::string read_checked_design(const Job& job);
  // Every colour of the job is in a slot of `loom`'s magazines (the start's check: the magazines may have
  // been changed since the job was added). JobError naming every colour in no slot.
  static void check_yarn(const Job& job, const firmware::LoomConfig& loom);

  // The file's text and its strict parser (exposed for tests and fuzzing); `source` names it in errors.
  static std::string format(const std::vector<Job>& jobs, std::uint32_t next_id);
  static JobQueue parse(const std::string& text, const std::string& source);

 private:
  explicit JobQueue(std::string path) : path_(std::move(path)) {}
  Job& mutable_job(std::uint32_t id);
  Job& mutable_current(const char* what);
  void save() const;

  std::string path_;
  std::vector<Job> jobs_;
  std::uint32_t next_id_ = 1;
};

}  // namespace loom::job
