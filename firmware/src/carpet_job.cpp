// See carpet_job.hpp.
#include "loom/firmware/carpet_job.hpp"

#include <memory>
#include <stdexcept>

#include "loom/design/design.hpp"
#include "loom/sequencer/knot_plan.hpp"

namespace loom::firmware {

CarpetJob::CarpetJob(const std::string& state_dir)
    : queue_(job::JobQueue::load(job::JobQueue::path_in(state_dir))) {
  refresh();
}

void CarpetJob::reload() {
  std::lock_guard<std::mutex> lock(mu_);
  queue_ = job::JobQueue::load(queue_.path());
  armed_id_ = 0;  // a new session: arm() says which job it weaves
  refresh();
}

std::uint32_t CarpetJob::armed_id() const {
  std::lock_guard<std::mutex> lock(mu_);
  return armed_id_;
}

std::vector<job::Job> CarpetJob::all_jobs() const {
  std::lock_guard<std::mutex> lock(mu_);
  return queue_.jobs();
}

job::Job CarpetJob::job_numbered(std::uint32_t id) const {
  std::lock_guard<std::mutex> lock(mu_);
  return queue_.job(id);
}

job::Job CarpetJob::add(const std::string& design_path, const LoomConfig& loom,
                        const job::JobLength& length) {
  std::lock_guard<std::mutex> lock(mu_);
  const job::Job j = queue_.add(design_path, loom, length);
  refresh();
  return j;
}

void CarpetJob::remove(std::uint32_t id) {
  std::lock_guard<std::mutex> lock(mu_);
  queue_.remove(id);
  refresh();
}

job::Job CarpetJob::start_over(std::uint32_t id) {
  std::lock_guard<std::mutex> lock(mu_);
  queue_.start_over(id);
  refresh();
  return queue_.job(id);
}

bool CarpetJob::in_use() const {
  std::lock_guard<std::mutex> lock(mu_);
  return job_.has_value();
}

std::uint32_t CarpetJob::carpet_done_id() const {
  std::lock_guard<std::mutex> lock(mu_);
  return carpet_done_id_;
}

job::Job CarpetJob::job() const {
  std::lock_guard<std::mutex> lock(mu_);
  return *job_;
}

bool CarpetJob::started() const {
  std::lock_guard<std::mutex> lock(mu_);
  return job_ && job_->state == job::JobState::kCurrent;
}

std::uint64_t CarpetJob::rows_done() const {
  std::lock_guard<std::mutex> lock(mu_);
  return rows_done_locked();
}

std::uint64_t CarpetJob::rows_left() const {
  std::lock_guard<std::mutex> lock(mu_);
  return job_ ? job_->length_rows - job_->progress.rows_done : 0;
}

// The job to weave: the armed one while it is queued or current (a queue changed under a session keeps
// what it weaves), else the current one, else the lowest-numbered queued one (the queue's order).
void CarpetJob::refresh() {
  job_.reset();
  carpet_done_id_ = 0;
  if (const job::Job* c = queue_.current()) {
    job_ = *c;
  } else {
    for (const job::Job& j : queue_.jobs()) {
      if (j.state == job::JobState::kQueued) {
        job_ = j;
        break;
      }
      if (j.state == job::JobState::kCarpetDone) carpet_done_id_ = j.id;
    }
  }
  if (armed_id_ == 0 || (job_ && job_->id == armed_id_)) return;
  for (const job::Job& j : queue_.jobs()) {
    if (j.id == armed_id_ && (j.state == job::JobState::kQueued || j.state == job::JobState::kCurrent))
      job_ = j;
  }
}

LoomConfig CarpetJob::config_for(const LoomConfig& loom) const {
  std::lock_guard<std::mutex> lock(mu_);
  if (!job_) throw job::JobError("no carpet job to weave");
  const job::Job& j = *job_;
  const std::string bytes = job::JobQueue::read_checked_design(j);
  LoomConfig c = loom;
  try {
    c.recipe.design = std::make_shared<const design::Design>(design::parse_design(bytes, j.design_path));
  } catch (const design::DesignError& e) {
    throw job::JobError("job " + std::to_string(j.id) + ": " + e.what());
  }
  c.recipe.design_file = j.design_path;
  const int loom_knots = sequencer::knots_per_row(loom.knotting, loom.machine_spec.width_m);
  if (c.recipe.design->width() != loom_knots) {
    throw job::JobError("job " + std::to_string(j.id) + ": the design " + j.design_path + " is " +
                        std::to_string(c.recipe.design->width()) + " knots wide; the loom (" + loom.source +
                        ") ties " + std::to_string(loom_knots) + " knots per row");
  }
  job::JobQueue::check_yarn(j, loom);
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    try {
      (void)knot_program(c, 0, 0);  // every knot of every row has a slot on this loom
    } catch (const std::invalid_argument& e) {
      throw job::JobError("job " + std::to_string(j.id) + ": " + e.what());
    }
  }
  return c;
}

std::uint64_t CarpetJob::arm(std::uint32_t counter_rows) {
  std::lock_guard<std::mutex> lock(mu_);
  credited_rows_ = counter_rows;
  armed_id_ = 0;
  refresh();
  if (job_ && job_->state == job::JobState::kCurrent && counter_rows > job_->progress.at_counter_rows) {
    // Rows whose counters reached the disk before a power cut kept the queue from hearing of them.
    if (queue_.advance(counter_rows)) {
      queue_.mark_carpet_done();
      refresh();  // the next queued job, if any, is what this session weaves
    } else {
      refresh();
    }
  }
  armed_id_ = job_ ? job_->id : 0;
  return rows_done_locked();
}

// The armed job as the queue has it now, or null when the queue no longer holds it to weave (it was
// removed or finished): then this session starts and credits nothing.
const job::Job* CarpetJob::armed_locked() const {
  if (armed_id_ == 0 || !job_ || job_->id != armed_id_) return nullptr;
  return &*job_;
}

bool CarpetJob::start(std::uint32_t counter_rows) {
  std::lock_guard<std::mutex> lock(mu_);
  const job::Job* j = armed_locked();
  if (j == nullptr || j->state == job::JobState::kCurrent) return false;
  queue_.start(j->id, counter_rows);
  credited_rows_ = counter_rows;
  refresh();
  return true;
}

bool CarpetJob::row_saved(std::uint32_t counter_rows) {
  std::lock_guard<std::mutex> lock(mu_);
  const job::Job* j = armed_locked();
  if (j == nullptr || counter_rows <= credited_rows_) return false;
  if (j->state != job::JobState::kCurrent) queue_.start(j->id, credited_rows_);
  credited_rows_ = counter_rows;
  const bool last = queue_.advance(counter_rows);
  if (last) queue_.mark_carpet_done();
  refresh();
  return last;
}

std::string CarpetJob::describe() const {
  std::lock_guard<std::mutex> lock(mu_);
  if (!job_) return "";
  const job::Job& j = *job_;
  return "job " + std::to_string(j.id) + " (design " + j.design_name + ", sha256 " + j.sha256.substr(0, 12) +
         "..): " + (j.state == job::JobState::kCurrent ? "row " : "queued, starts at row ") +
         std::to_string(j.next_row()) + " of " + std::to_string(j.length_rows) + " next";
}

std::string CarpetJob::status_fields() const {
  std::lock_guard<std::mutex> lock(mu_);
  if (!job_) return "";
  return " job=" + std::to_string(job_->id) + " job_row=" + std::to_string(job_->next_row()) + "/" +
         std::to_string(job_->length_rows) +
         (job_->state == job::JobState::kCurrent ? "" : " job_state=queued");
}

}  // namespace loom::firmware
