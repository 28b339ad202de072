#include "fault_history.hpp"

#include <sstream>
#include <vector>

namespace loom::panel {

namespace {

// "2026-11-23T20:15:03Z": the shape FaultHistory writes (UTC, seconds).
bool utc_stamp(const std::string& s) {
  if (s.size() != 20 || s[4] != '-' || s[7] != '-' || s[10] != 'T' || s[13] != ':' || s[16] != ':' ||
      s[19] != 'Z') {
    return false;
  }
  for (std::size_t i : {0u, 1u, 2u, 3u, 5u, 6u, 8u, 9u, 11u, 12u, 14u, 15u, 17u, 18u}) {
    if (s[i] < '0' || s[i] > '9') return false;
  }
  return true;
}

}  // namespace

nlohmann::json fault_history_json(const std::string& reply, std::size_t keep) {
  std::vector<std::string> lines;
  std::string note;
  std::istringstream in(reply);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line.rfind("no faults recorded", 0) == 0) {
      note = line;
      continue;
    }
    lines.push_back(line);
  }
  const std::size_t first = lines.size() > keep ? lines.size() - keep : 0;
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = first; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    // time kind loom name rest...
    std::size_t p[4];
    std::size_t at = 0;
    bool ok = true;
    for (auto& sp : p) {
      sp = l.find(' ', at);
      if (sp == std::string::npos) {
        ok = false;
        break;
      }
      at = sp + 1;
    }
    if (ok && utc_stamp(l.substr(0, p[0]))) {
      out.push_back({{"time", l.substr(0, p[0])},
                     {"kind", l.substr(p[0] + 1, p[1] - p[0] - 1)},
                     {"name", l.substr(p[2] + 1, p[3] - p[2] - 1)},
                     {"detail", l.substr(p[3] + 1)},
                     {"line", l}});
    } else {
      out.push_back({{"line", l}});
    }
  }
  return {{"lines", out}, {"total", lines.size()}, {"shown", out.size()}, {"note", note}};
}

}  // namespace loom::panel
