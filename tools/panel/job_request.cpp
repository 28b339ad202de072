// See job_request.hpp.
#include "job_request.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

namespace loom::panel {
namespace {

constexpr std::size_t kMaxDesignPath = 256;

bool digits(const std::string& s, std::size_t max_len) {
  return !s.empty() && s.size() <= max_len && s.find_first_not_of("0123456789") == std::string::npos;
}

// A job number as the loom counts them: 1 to 4294967295.
bool job_number(const std::string& s) {
  return digits(s, 10) && std::stoull(s) >= 1 && std::stoull(s) <= 4294967295ull;
}

// Digits with at most one '.', and at least one digit: "2", "1.5", ".5".
bool decimal(const std::string& s) {
  if (s.empty() || s.size() > 12 || s.find_first_not_of("0123456789.") != std::string::npos) return false;
  return std::count(s.begin(), s.end(), '.') <= 1 && s.find_first_of("0123456789") != std::string::npos;
}

// What the loom's request line carries of a design path: printable ASCII without spaces (a space would
// end the field and start another), from '/'.
std::string design_refusal(const std::string& p) {
  if (p.front() != '/') return "design: an absolute path on the loom's board (from /)";
  if (p.size() > kMaxDesignPath) return "design: a path of at most 256 characters";
  const bool plain = std::all_of(p.begin(), p.end(), [](char c) { return c > ' ' && c < 0x7F; });
  if (!plain) return "design: a path of printable ASCII without spaces (rename the file on the board)";
  return "";
}

}  // namespace

JobVerb job_verb(const std::string& word) {
  if (word == "add") return JobVerb::kAdd;
  if (word == "remove") return JobVerb::kRemove;
  if (word == "start-over") return JobVerb::kStartOver;
  return JobVerb::kUnknown;
}

std::string job_line(JobVerb verb, const ParamOf& param, std::string& why) {
  why.clear();
  const auto refuse = [&](const std::string& w) {
    why = w;
    return std::string();
  };
  if (verb == JobVerb::kUnknown) return refuse("not a job verb (add, remove, start-over)");
  const auto id = param("id"), design = param("design");
  const auto rows = param("rows"), metres = param("metres"), repeat = param("repeat");
  if (verb != JobVerb::kAdd) {
    const std::string word = verb == JobVerb::kRemove ? "remove" : "start-over";
    if (design || rows || metres || repeat) return refuse("job " + word + " takes only id=N");
    if (!id) return refuse("job " + word + " needs id=N (the job's number in the queue)");
    if (!job_number(*id)) return refuse("id: a job number, 1 to 4294967295");
    return "job " + word + " id=" + *id;
  }
  if (id) return refuse("job add takes no id (the loom numbers the job)");
  if (!design) return refuse("job add needs design=PATH (the design file on the loom's board)");
  if (auto w = design_refusal(*design); !w.empty()) return refuse(w);
  if (int(rows.has_value()) + int(metres.has_value()) + int(repeat.has_value()) > 1)
    return refuse("one length at most: rows, metres or repeat");
  std::string line = "job add design=" + *design;
  if (rows) {
    if (!digits(*rows, 10)) return refuse("rows: a whole number of rows");
    line += " rows=" + *rows;
  } else if (metres) {
    if (!decimal(*metres)) return refuse("metres: a decimal number (e.g. 1.8)");
    line += " metres=" + *metres;
  } else if (repeat) {
    if (!digits(*repeat, 7)) return refuse("repeat: a whole number of repeats of the design");
    line += " repeat=" + *repeat;
  }
  return line;
}

nlohmann::json job_list_json(const std::string& text) {
  nlohmann::json rows = nlohmann::json::array();
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    // "1     queued       rug.csv      0123456789ab.. row 1 of 6 next": the design's name may hold spaces,
    // so it is what lies between the state and the 12-digit hash with its "..".
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string t; words >> t;) w.push_back(t);
    if (w.size() < 5 || !job_number(w[0])) continue;
    std::size_t hash = 0;
    for (std::size_t i = w.size() - 1; i >= 3; --i) {
      const std::string& t = w[i];
      if (t.size() == 14 && t.compare(12, 2, "..") == 0 && t.find_first_not_of("0123456789abcdef") == 12) {
        hash = i;
        break;
      }
    }
    if (hash == 0) continue;
    std::string design, progress;
    for (std::size_t i = 2; i < hash; ++i) design += (i > 2 ? " " : "") + w[i];
    for (std::size_t i = hash + 1; i < w.size(); ++i) progress += (i > hash + 1 ? " " : "") + w[i];
    rows.push_back({{"id", std::stoull(w[0])},
                    {"state", w[1]},
                    {"design", design},
                    {"sha256", w[hash].substr(0, 12)},
                    {"progress", progress}});
  }
  return {{"jobs", rows}, {"text", text}};
}

}  // namespace loom::panel
