// The job queue in words, as `loomctl job list|show` and the control socket's `job list|show` print it:
// one wording wherever a weaver reads it (the service answers from the queue it holds, the offline CLI
// from jobs.txt).
#pragma once

#include <string>
#include <vector>

#include "loom/job/job_queue.hpp"

namespace loom::job {

// "row R of L next" or "all L rows woven".
std::string progress_text(const Job& j);
// A header and one line per job (number, state, design, hash, progress); `where` names the queue's file
// in the line said when it has no job.
std::string list_text(const std::vector<Job>& jobs, const std::string& where);
// One job in full: design, file and whether it is unchanged, size, length, weaving, progress, yarn.
std::string show_text(const Job& j);

}  // namespace loom::job
