// The production record of the carpet job being woven (loom::record: production.sqlite in the state
// directory), fed from the run's events on the reporter's side — never from the loop. Each event's
// end-of-tick state says where the machine is from that instant: the time since the previous event goes to
// the state it left, so the states' times add up to the job's wall time by construction. A row's end writes
// its knots and yarn, durable when the row's event is handled; a fault is written at once.
//
// Instants are the wall clock at arming plus the ticks since, so they never go back. A simulation in
// virtual time runs ahead of the wall clock: its instants start after the record's last commit of the job.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "loom/firmware/runner.hpp"
#include "loom/job/job_queue.hpp"
#include "loom/record/production_record.hpp"

namespace loom::design {
class Design;
}
namespace loom::sequencer {
class KnotProgram;
}

namespace loom::firmware {

class JobRecorder {
 public:
  // Opens the record of `state_dir` and begins (or resumes) `job`, whose carpet row `job.progress.rows_done`
  // was woven by production row `counter_rows`. record::RecordError when the record cannot be kept (another
  // writer, a file that is not a loomctl record, a job recorded as ended).
  JobRecorder(const std::string& state_dir, const job::Job& job, std::uint32_t counter_rows, double period_s,
              bool virtual_time);

  // A run event: the state from its tick on; a row's knots and yarn (from the design row it tied); a fault,
  // or its acknowledgement.
  void on_event(const RunEvent& e, const sequencer::KnotProgram* program, const design::Design* design);
  // The run ended at `tick`: its time committed; with `carpet_done` the job's end.
  void finish(hal::Tick tick, bool carpet_done);

 private:
  record::WallNs at(hal::Tick t) const { return wall0_ + static_cast<record::WallNs>(t) * period_ns_; }

  std::unique_ptr<record::ProductionRecord> rec_;
  std::uint64_t job_rows_at_arm_;
  std::uint32_t counter_rows_at_arm_;
  std::int64_t period_ns_;
  record::WallNs wall0_ = 0;
  bool faulted_ = false;
};

// The record's state for a machine state at the end of a tick (the heads waiting for the weaver count as
// waiting, whatever the sequencer's state).
record::MachineState record_state(sequencer::State s, bool weaver_asked);

}  // namespace loom::firmware
