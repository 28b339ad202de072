// See job_verbs.hpp.
#include "loom/firmware/serve/job_verbs.hpp"

#include <string>

#include "loom/job/job_text.hpp"

namespace loom::firmware::serve {
namespace {

job::JobLength length_of(const ParsedRequest& r) {
  job::JobLength l;  // the protocol checked the numbers' shape and range
  if (!r.field("rows").empty()) l.rows = std::stoull(r.field("rows"));
  if (!r.field("metres").empty()) l.metres = std::stod(r.field("metres"));
  if (!r.field("repeat").empty()) l.repeats = static_cast<std::uint32_t>(std::stoul(r.field("repeat")));
  return l;
}

std::string rows_text(std::uint64_t rows) {
  return std::to_string(rows) + (rows == 1 ? " row" : " rows");
}

// Whether the armed job `id` may be changed now: the loom stands done (no start in this session), or
// the gate closes before any start. "" when it may, else why not.
std::string close_gate_for(std::uint32_t id, OperatorLink& link, sequencer::State state) {
  if (state == sequencer::State::kDone) {
    link.queue_gate.store(OperatorLink::kGateQueueChanged, std::memory_order_release);
    return "";
  }
  if (link.close_for_queue_change()) return "";
  const std::string s = sequencer::state_name(state);
  if (state == sequencer::State::kFault) {
    return "the loom began job " + std::to_string(id) +
           " and stands in a fault: acknowledge it (ctl ack), then " + "stop at the row end (ctl stop)";
  }
  return "the loom is weaving job " + std::to_string(id) + " (state " + s +
         "): stop it at the row end first (ctl stop)";
}

}  // namespace

JobVerbResult carry_out_job_verb(const ParsedRequest& r, CarpetJob& jobs, const LoomConfig& loom,
                                 OperatorLink& link, sequencer::State state) {
  JobVerbResult out;
  const std::string& verb = r.arg;
  const auto refuse = [&](const std::string& why) {
    out.reply = "refused: job " + verb + ": " + why + "\n";
    return out;
  };
  const std::uint32_t id = r.field("id").empty() ? 0 : static_cast<std::uint32_t>(std::stoul(r.field("id")));
  const std::uint32_t armed = jobs.armed_id();
  try {
    if (verb == "list") {
      out.reply = job::list_text(jobs.all_jobs(), "this loom's job queue");
      return out;
    }
    if (verb == "show") {
      out.reply = job::show_text(jobs.job_numbered(id));
      return out;
    }
    if (verb == "add") {
      const job::Job j = jobs.add(r.field("design"), loom, length_of(r));
      out.reply = "ok job add: job " + std::to_string(j.id) + ": " + j.design_name + " (sha256 " +
                  j.sha256.substr(0, 12) + "..), " + rows_text(j.length_rows) + ", queued";
      if (armed == 0) {
        out.rearm = true;
        const bool standing = state == sequencer::State::kIdle || state == sequencer::State::kDone;
        out.reply += standing ? "; the loom arms it (start it at the machine)"
                              : "; the loom weaves on and arms it when it next stands";
      }
      out.reply += "\n";
    } else {  // remove, start-over: the armed job only behind the gate
      if (id == armed) {
        if (const std::string why = close_gate_for(id, link, state); !why.empty()) return refuse(why);
      }
      if (verb == "remove") {
        jobs.remove(id);
        out.reply =
            "ok job remove: job " + std::to_string(id) + " removed from the queue (its record stays)\n";
      } else {
        const job::Job j = jobs.start_over(id);
        out.reply = "ok job start-over: job " + std::to_string(id) + " starts over at row 1 (" +
                    job::job_state_name(j.state) + ", weaving " + std::to_string(j.weaving) + ")\n";
      }
      out.rearm = id == armed || armed == 0;
    }
  } catch (const job::JobError& e) {
    return refuse(e.what());
  } catch (const std::exception& e) {  // the queue's write failed: the old queue stays
    return refuse(std::string("the job queue was not changed: ") + e.what());
  }
  if (out.rearm) link.post(Command::kRearm);
  return out;
}

}  // namespace loom::firmware::serve
