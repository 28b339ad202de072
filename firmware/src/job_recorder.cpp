// See job_recorder.hpp.
#include "loom/firmware/job_recorder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <vector>

#include "loom/design/design.hpp"
#include "loom/sequencer/knot_program.hpp"

namespace loom::firmware {

namespace {
record::WallNs wall_now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}
}  // namespace

record::MachineState record_state(sequencer::State s, bool weaver_asked) {
  using S = sequencer::State;
  using M = record::MachineState;
  if (weaver_asked) return M::kWaitingForWeaver;
  switch (s) {
    case S::kKnotting:
      return M::kKnotting;
    case S::kAwaitKnotting:
      return M::kWaitingForWeaver;  // the weaver knots the row by hand
    case S::kPaused:
      return M::kPaused;
    case S::kFault:
      return M::kFaulted;
    case S::kIdle:
    case S::kDone:
      return M::kIdle;
    default:
      return M::kWeaving;  // enabling, homing, the shed, pick, beat and row end
  }
}

JobRecorder::JobRecorder(const std::string& state_dir, const job::Job& job, std::uint32_t counter_rows,
                         double period_s, bool virtual_time)
    : rec_(std::make_unique<record::ProductionRecord>(record::ProductionRecord::path_in(state_dir))),
      job_rows_at_arm_(job.progress.rows_done),
      counter_rows_at_arm_(counter_rows),
      period_ns_(static_cast<std::int64_t>(std::llround(period_s * 1e9))) {
  wall0_ = wall_now();
  if (virtual_time) {
    // A simulated loom's instants run ahead of the wall clock by its machine time: this run starts after
    // the latest the record holds (any job, any weaving), so the loom's record never goes back in time.
    if (const auto latest = record::read_latest_instant(record::ProductionRecord::path_in(state_dir))) {
      wall0_ = std::max(wall0_, *latest);
    }
  }
  rec_->begin_job({job.id, job.weaving, job.design_name, job.sha256, job.length_rows},
                  record::MachineState::kIdle, wall0_);
}

void JobRecorder::on_event(const RunEvent& e, const sequencer::KnotProgram* program,
                           const design::Design* design) {
  const record::WallNs t = at(e.tick);
  switch (e.kind) {
    case RunEvent::Kind::kFault:
    case RunEvent::Kind::kOverrunStop:
      if (!faulted_) rec_->fault(sequencer::fault_name(e.fault), sequencer::fault_code(e.fault), t);
      faulted_ = true;
      break;
    case RunEvent::Kind::kRowDone: {
      record::RowDone r;
      r.row = job_rows_at_arm_ + (e.counters.rows - counter_rows_at_arm_);
      r.knots_by_heads = static_cast<std::uint32_t>(std::max(0, e.row.knots_tied));
      r.knots_retried = static_cast<std::uint32_t>(std::max(0, e.row.knots_retried));
      r.knots_by_hand = static_cast<std::uint32_t>(std::max(0, e.row.knots_by_hand));
      if (program != nullptr && design != nullptr && e.counters.rows > 0) {
        std::vector<std::uint32_t> knots(design->palette().size(), 0);
        for (const std::uint16_t k : design->row(program->design_row(e.counters.rows - 1))) ++knots[k];
        for (std::size_t i = 0; i < knots.size(); ++i) {
          if (knots[i] != 0) r.yarn[design->palette()[i].code] = knots[i];
        }
      }
      rec_->set_state(record_state(e.state, false), t);
      rec_->row_done(r, t);
      return;
    }
    case RunEvent::Kind::kReloaded:
      return;  // the levels changed, not the machine's state (a reload that answers a request: the
               // knotting goes on, and its next event says so)
    default:
      break;
  }
  if (faulted_ && e.state != sequencer::State::kFault) {
    rec_->fault_cleared(t);  // acknowledged: the loom left the fault
    faulted_ = false;
  }
  rec_->set_state(record_state(e.state, e.kind == RunEvent::Kind::kWeaverRequest), t);
}

void JobRecorder::finish(hal::Tick tick, bool carpet_done) {
  if (carpet_done) {
    rec_->end_job(at(tick));
  } else {
    rec_->commit(at(tick));
  }
}

}  // namespace loom::firmware
