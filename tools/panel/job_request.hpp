// The panel's side of the loom's job queue verbs (loomctl serve's `job ...` socket requests, issue 29):
// the request line a POST becomes, its shape checked here before anything reaches the loom, and the
// loom's `job list` text read back as rows for the page. The loom checks again (ranges, the design file,
// who may change the queue) and audits; the panel only refuses what is not even a well-formed request.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace loom::panel {

// The verbs a panel forwards that change the queue: add, remove, start-over (each needs a paired client).
// list and show are read with GET routes.
enum class JobVerb { kUnknown, kAdd, kRemove, kStartOver };
JobVerb job_verb(const std::string& word);

// A request parameter by name (query or form body): nullopt when absent; an empty value counts as absent.
using ParamOf = std::function<std::optional<std::string>(const char* name)>;

// The socket line for `verb` ("job add design=/ABS/PATH rows=6", "job remove id=2"), or "" with `why` set:
//   add        design=/ABSOLUTE/PATH (printable ASCII, no spaces, at most 256 characters) and at most one
//              of rows=R (digits), metres=M (digits with one optional '.'), repeat=K (digits);
//   remove, start-over   id=N (digits, 1 to 4294967295).
// Any other parameter of the three verbs' (id for add, design or a length for remove) is refused.
std::string job_line(JobVerb verb, const ParamOf& param, std::string& why);

// The loom's `job list` text as {"jobs": [{"id", "state", "design", "sha256", "progress"}...], "text"}: a
// line that does not read as a job row is left out of "jobs" (the text keeps it).
nlohmann::json job_list_json(const std::string& text);

}  // namespace loom::panel
