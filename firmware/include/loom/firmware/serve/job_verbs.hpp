// The control socket's `job VERB` requests, carried out by the service on the job queue it holds (the
// offline `loomctl job` refuses to change it while serve runs): list and show read; add, remove and
// start-over change it — the desk lets those through only from a trusted station and audits them.
//
// What the armed session weaves is never changed under it: removing or starting over the armed job
// closes OperatorLink::queue_gate first, and is refused once the loom has started that job in this
// session (stop it at the row end first). A change that alters what the standing loom would weave posts
// Command::kRearm, so the service arms again from the queue; it never starts anything (a job is started
// by `start`, at the machine).
#pragma once

#include <string>

#include "loom/config/config.hpp"
#include "loom/firmware/carpet_job.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/firmware/serve/control_protocol.hpp"

namespace loom::firmware::serve {

struct JobVerbResult {
  std::string reply;   // "ok job VERB: ..." or "refused: job VERB: why" (list and show: their text)
  bool rearm = false;  // Command::kRearm was posted
};

// `r` is a parsed `job ...` request; `state`: the loom's state as the desk saw it. Non-RT (control thread);
// the caller serialises it with arming.
JobVerbResult carry_out_job_verb(const ParsedRequest& r, CarpetJob& jobs, const LoomConfig& loom,
                                 OperatorLink& link, sequencer::State state);

}  // namespace loom::firmware::serve
