// See job_feed.hpp.
#include "loom/firmware/job_feed.hpp"

#include <algorithm>
#include <optional>
#include <system_error>

#include "loom/design/design.hpp"
#include "loom/job/job_queue.hpp"
#include "loom/job/yarn_stock.hpp"

namespace loom::firmware {

namespace {

// The job a panel shows: the current one, else the first queued, else the last carpet_done.
const job::Job* shown_job(const job::JobQueue& q) {
  if (const job::Job* c = q.current()) return c;
  const job::Job* done = nullptr;
  for (const job::Job& j : q.jobs()) {
    if (j.state == job::JobState::kQueued) return &j;
    if (j.state == job::JobState::kCarpetDone) done = &j;
  }
  return done;
}

std::filesystem::file_time_type mtime_of(const std::string& path) {
  std::error_code ec;
  const auto t = std::filesystem::last_write_time(path, ec);
  return ec ? std::filesystem::file_time_type{} : t;
}

}  // namespace

JobFeed::JobFeed(std::string state_dir, const std::string& lcm_url, const std::string& loom_id)
    : state_dir_(std::move(state_dir)),
      events_(lcm_url, std::string(telemetry::kDefaultChannelPrefix), loom_id) {}

void JobFeed::armed(const Machine& machine) {
  std::lock_guard<std::mutex> lock(mu_);
  period_s_ = machine.config().sequencer.period_s;
  report_.stripe = 0;
  report_.slot_colours.clear();
  report_.stock.clear();
  report_.cycles_done = 0;
  if (const sequencer::KnotProgram* p = machine.knot_program(); p != nullptr && p->heads() > 0) {
    report_.stripe = p->stripe();
    report_.knots_per_slot = p->knots_per_slot();
    for (int s = 0; s < p->slots(); ++s) report_.slot_colours.push_back(p->slot_colour(s));
    // Full until magazines.txt says otherwise (the session arms with full magazines without it).
    report_.stock.assign(
        static_cast<std::size_t>(p->heads()),
        std::vector<std::int32_t>(static_cast<std::size_t>(p->slots()), p->knots_per_slot()));
  }
  carpet_key_.clear();  // sent again at arming: a panel started with the session has it at once
  try {
    publish_locked();
  } catch (const std::exception&) {
    // A queue that cannot be read now was refused at arming already; the panel hears at the next row.
  }
}

void JobFeed::on_event(const RunEvent& e) noexcept {
  std::lock_guard<std::mutex> lock(mu_);
  try {
    if (e.kind == RunEvent::Kind::kRowDone) {
      if (e.stock_known) {  // as the record keeps them (magazines.txt, read again below, is the authority)
        for (std::size_t h = 0; h < report_.stock.size(); ++h) {
          for (std::size_t s = 0; s < report_.stock[h].size(); ++s)
            report_.stock[h][s] = std::max(0, e.stock[h][s]);
        }
      }
      // A whole row: the knotting before it and the weaving (the heads' and the weaver's time are inside).
      const double row_s = static_cast<double>(e.row.total_ticks + e.row.knotting_ticks) * period_s_;
      if (report_.job_id != 0 && report_.state == "current") {
        if (timed_job_ != report_.job_id) {
          timed_job_ = report_.job_id;
          timed_s_ = 0.0;
          timed_rows_ = 0;
        }
        timed_s_ += row_s;
        ++timed_rows_;
      }
      report_.cycles_done = 0;
      publish_locked();
    } else if (e.kind == RunEvent::Kind::kKnotProgress) {
      report_.cycles_done = e.counters.knot.cycles_done;
      const auto now = std::chrono::steady_clock::now();
      if (now - progress_sent_ < std::chrono::seconds(1)) return;
      progress_sent_ = now;
      publish_locked();
    }
  } catch (const std::exception&) {
    // jobs.txt unreadable for a moment: the next event or poll says it again.
  }
}

void JobFeed::poll() noexcept {
  std::lock_guard<std::mutex> lock(mu_);
  try {
    // Again when a file changed, and every 10 s in any case: a panel that joins while the loom stands
    // (waiting for the start, carpet_done) or an lcmlog replayed from its middle learns the job within 10 s.
    if (mtime_of(job::JobQueue::path_in(state_dir_)) != queue_mtime_ ||
        mtime_of(job::YarnStock::path_in(state_dir_)) != magazines_mtime_ ||
        std::chrono::steady_clock::now() - job_sent_ >= telemetry::kCarpetRepeat) {
      publish_locked();
    }
  } catch (const std::exception&) {
  }
  events_.repeat_carpet();
}

// The levels kept in magazines.txt (written at row ends and reloads), when they are for these magazines.
void JobFeed::read_magazines() {
  const std::string path = job::YarnStock::path_in(state_dir_);
  magazines_mtime_ = mtime_of(path);
  if (report_.stock.empty()) return;
  std::optional<job::YarnStock> kept;
  try {
    kept = job::YarnStock::load(path);
  } catch (const std::exception&) {
    return;  // not a magazines file: serve says so at arming; the levels counted stand
  }
  const int heads = static_cast<int>(report_.stock.size()),
            slots = static_cast<int>(report_.slot_colours.size());
  if (!kept || !kept->mismatch(heads, slots, report_.knots_per_slot).empty()) return;
  for (int h = 0; h < heads; ++h) {
    for (int s = 0; s < slots; ++s)
      report_.stock[static_cast<std::size_t>(h)][static_cast<std::size_t>(s)] = kept->knots(h, s);
  }
}

void JobFeed::publish_locked() {
  read_magazines();
  queue_mtime_ = mtime_of(job::JobQueue::path_in(state_dir_));
  const job::JobQueue q = job::JobQueue::load(job::JobQueue::path_in(state_dir_));
  telemetry::JobReport& r = report_;
  r.queue.clear();
  for (const job::Job& j : q.jobs()) {
    if (j.state == job::JobState::kRemoved) continue;
    r.queue.push_back(
        {j.id, j.design_name, job::job_state_name(j.state), j.progress.rows_done, j.length_rows});
  }
  const job::Job* j = shown_job(q);
  r.job_id = j ? j->id : 0;
  r.state = j ? job::job_state_name(j->state) : "";
  r.design_name = j ? j->design_name : "";
  r.design_hash = j ? j->sha256.substr(0, 12) : "";
  r.width = j ? j->knots_per_row : 0;
  r.design_rows = j ? j->design_rows : 0;
  r.rows_done = j ? j->progress.rows_done : 0;
  r.rows_total = j ? j->length_rows : 0;
  r.row_mean_s =
      j && timed_job_ == j->id && timed_rows_ > 0 ? timed_s_ / static_cast<double>(timed_rows_) : -1.0;
  events_.publish_job(r);
  job_sent_ = std::chrono::steady_clock::now();
  // The shown job's knot map, read from its file (checked against the job's hash) when the job changes.
  const std::string key = j ? std::to_string(j->id) + " " + j->sha256 : std::string();
  if (key == carpet_key_) return;
  carpet_key_ = key;
  std::shared_ptr<const design::Design> d;
  if (j) {
    try {
      d = std::make_shared<const design::Design>(
          design::parse_design(job::JobQueue::read_checked_design(*j), j->design_path));
    } catch (const std::exception&) {
      // A changed or missing design file: the loom refuses the job and says why; the panel shows no map.
    }
  }
  events_.set_carpet(d, r.job_id, r.design_hash);
}

}  // namespace loom::firmware
