// The carpet job a session weaves, seen from the loop's side of loom::job's queue (jobs.txt in the state
// directory): at arming, which job and which design (the file's hash checked, its yarn in the magazines);
// the job started at the machine; after each row's counters are on disk, the rows credited to the job;
// after its last row, carpet_done. Non-RT: arming and the reporter's saves only.
//
// A state directory whose queue has no job current or queued weaves as before (the recipe's design and
// the design book); a queue that has one weaves the job, whose design replaces the recipe's.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/job/job_queue.hpp"

namespace loom::firmware {

// The production row a job's carpet began at: `counter_rows` now, less the job's rows woven (`job_rows`).
inline std::uint32_t carpet_began(std::uint32_t counter_rows, std::uint64_t job_rows) {
  return job_rows >= counter_rows ? 0 : counter_rows - static_cast<std::uint32_t>(job_rows);
}

class CarpetJob {
 public:
  // The queue of `state_dir` (absent: empty). job::JobError on a bad file, naming file:line and field.
  explicit CarpetJob(const std::string& state_dir);

  // Reads the queue again (serve, at each arming: only the service changes it while it holds the state
  // directory). job::JobError on a bad file; the queue read before stays.
  void reload();

  // The job the session was armed with (arm()), 0 when none: only it is started and credited in this
  // session, whatever the queue's verbs do meanwhile (a job added, another started over).
  std::uint32_t armed_id() const;

  // serve's queue verbs (the control socket's `job ...`), on the queue kept here and written through
  // (job::JobQueue's checks and refusals, as job::JobError). The service decides first whether the armed
  // job may be changed (OperatorLink::queue_gate).
  std::vector<job::Job> all_jobs() const;
  job::Job job_numbered(std::uint32_t id) const;
  job::Job add(const std::string& design_path, const LoomConfig& loom, const job::JobLength& length);
  void remove(std::uint32_t id);
  job::Job start_over(std::uint32_t id);

  // The queue has a job to weave: the current one, or a queued one a start at the machine begins.
  bool in_use() const;
  // The last job woven to its end when nothing is current or queued (the loom waits for the cut-off and
  // the next job); 0 when none.
  std::uint32_t carpet_done_id() const;
  // The job to weave (in_use() only): the current one, else the lowest-numbered queued one (a copy).
  job::Job job() const;
  bool started() const;

  // The loom's description with the job's design as its recipe: the design file must still have the
  // bytes it was added with and fit the loom (width, every colour in a magazine slot). job::JobError
  // naming the job, the file and the reason otherwise — a changed design is never silently mixed.
  LoomConfig config_for(const LoomConfig& loom) const;
  // Arming: rows counted since the job's last write (a power cut between the counters' save and the
  // queue's) are credited to it, and the job to weave becomes the armed one. Returns the rows of the
  // carpet woven.
  std::uint64_t arm(std::uint32_t counter_rows);
  std::uint64_t rows_done() const;
  std::uint64_t rows_left() const;

  // The start at the machine: a queued job becomes current, based at production row `counter_rows`.
  // Nothing when it is current already. Returns true when this call started it. (A row saved while the
  // job is still queued starts it at the armed row: a start button's press is heard after the loop acted.)
  bool start(std::uint32_t counter_rows);
  // After a row's counters were saved (production row count `counter_rows`): the rows since the last
  // credit go to the job. Returns true once, when the carpet's last row is woven (the job is then
  // carpet_done and nothing is current).
  bool row_saved(std::uint32_t counter_rows);

  // "job N (design NAME, sha256 ABC..): row R of L next" — for the armed line and ctl status.
  std::string describe() const;
  // " job=N job_row=R/L" for ctl status ("" without a job).
  std::string status_fields() const;

 private:
  void refresh();
  const job::Job* armed_locked() const;
  std::uint64_t rows_done_locked() const { return job_ ? job_->progress.rows_done : 0; }

  mutable std::mutex mu_;  // the control thread starts a job, the reporter credits rows
  job::JobQueue queue_;
  std::optional<job::Job> job_;  // a copy of the queue's current or next job
  std::uint32_t carpet_done_id_ = 0;
  std::uint32_t credited_rows_ = 0;  // production rows last credited
  std::uint32_t armed_id_ = 0;       // the job this session weaves (0: none)
};

}  // namespace loom::firmware
