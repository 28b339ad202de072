// See report_format.hpp.
#include "loom/record/report_format.hpp"

#include <time.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

namespace loom::record {
namespace {

double seconds(std::int64_t ns) {
  return static_cast<double>(ns) / 1e9;
}

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// A fault's downtime: to its acknowledgement, or (still open) to the record's end.
std::int64_t downtime_ns(const JobReport& r, const FaultRecord& f) {
  return (f.cleared ? *f.cleared : (r.ended ? *r.ended : r.recorded_until)) - f.at;
}

// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

std::string iso_utc(WallNs t) {
  const std::int64_t sec = t >= 0 ? t / 1'000'000'000 : (t - 999'999'999) / 1'000'000'000;
  const std::int64_t ms = (t - sec * 1'000'000'000) / 1'000'000;
  const time_t tt = static_cast<time_t>(sec);
  struct tm tm {};
  gmtime_r(&tt, &tm);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1,
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}

std::string report_text(const JobReport& r) {
  std::ostringstream os;
  os << "job " << r.id << ": " << r.design_name << " (sha256 " << r.sha256.substr(0, 12) << "...), "
     << r.length_rows << " rows\n";
  if (r.weavings > 1) {
    os << "  weaving   " << r.weaving << " of " << r.weavings << " (the job was started over; report job "
       << r.id << " --weaving K shows another)\n";
  }
  os << "  started   " << iso_utc(r.started) << "\n";
  const bool started_over = !r.ended && r.weaving < r.weavings;
  os << "  "
     << (r.ended        ? "ended     " + iso_utc(*r.ended)
         : started_over ? "recorded  to " + iso_utc(r.recorded_until) + " (started over before its end)"
                        : "recorded  to " + iso_utc(r.recorded_until) + " (not ended)")
     << "\n";
  os << "  wall time " << fixed(seconds(r.wall_ns()), 3) << " s\n";
  os << "  rows      " << r.rows << " recorded (last row " << r.last_row << " of " << r.length_rows << ")\n";
  os << "  knots     " << r.knots_by_heads << " by the heads, " << r.knots_retried << " retried, "
     << r.knots_by_hand << " by hand\n";
  os << "  machine time by state (OPC UA for Machinery state):\n";
  for (int s = 0; s < kMachineStates; ++s) {
    const auto st = static_cast<MachineState>(s);
    const double sec = seconds(r.state_ns[static_cast<std::size_t>(s)]);
    const double share = r.wall_ns() > 0 ? 100.0 * sec / seconds(r.wall_ns()) : 0.0;
    char line[160];
    std::snprintf(line, sizeof line, "    %-19s %14.3f s %6.1f %%  (%s)\n", machine_state_name(st), sec,
                  share, opcua_machinery_state(st));
    os << line;
  }
  os << "  yarn      ";
  if (r.yarn.empty()) os << "none recorded";
  bool first = true;
  for (const auto& [colour, knots] : r.yarn) {
    os << (first ? "" : ", ") << colour << " " << knots << " knots";
    first = false;
  }
  os << "\n  faults    " << r.faults.size() << "\n";
  for (const FaultRecord& f : r.faults) {
    os << "    " << iso_utc(f.at) << " " << f.name << " (code " << f.code << "): downtime "
       << fixed(seconds(downtime_ns(r, f)), 3) << " s" << (f.cleared ? "" : " (not acknowledged)") << "\n";
  }
  return os.str();
}

std::string report_csv(const JobReport& r) {
  std::ostringstream os;
  const auto line = [&](const std::string& item, const std::string& name, const std::string& value,
                        const std::string& detail = "") {
    os << csv_field(item) << "," << csv_field(name) << "," << csv_field(value) << "," << csv_field(detail)
       << "\n";
  };
  os << "item,name,value,detail\n";
  line("job", "id", std::to_string(r.id));
  line("job", "weaving", std::to_string(r.weaving), "of " + std::to_string(r.weavings));
  line("job", "design", r.design_name);
  line("job", "sha256", r.sha256);
  line("job", "length_rows", std::to_string(r.length_rows));
  line("job", "started", iso_utc(r.started));
  line("job", "ended", r.ended ? iso_utc(*r.ended) : "");
  line("job", "recorded_until", iso_utc(r.recorded_until));
  line("job", "wall_s", fixed(seconds(r.wall_ns()), 6));
  line("rows", "recorded", std::to_string(r.rows));
  line("rows", "last", std::to_string(r.last_row));
  line("knots", "by_heads", std::to_string(r.knots_by_heads));
  line("knots", "retried", std::to_string(r.knots_retried));
  line("knots", "by_hand", std::to_string(r.knots_by_hand));
  for (int s = 0; s < kMachineStates; ++s) {
    const auto st = static_cast<MachineState>(s);
    line("state_s", machine_state_name(st), fixed(seconds(r.state_ns[static_cast<std::size_t>(s)]), 6),
         opcua_machinery_state(st));
  }
  for (const auto& [colour, knots] : r.yarn) line("yarn_knots", colour, std::to_string(knots));
  for (const FaultRecord& f : r.faults) {
    line("fault", f.name, fixed(seconds(downtime_ns(r, f)), 6),
         iso_utc(f.at) + " code " + std::to_string(f.code) + (f.cleared ? "" : " not acknowledged"));
  }
  return os.str();
}

std::string report_json(const JobReport& r) {
  nlohmann::ordered_json j;
  j["job"] = r.id;
  j["weaving"] = r.weaving;
  j["weavings"] = r.weavings;
  j["design"] = r.design_name;
  j["sha256"] = r.sha256;
  j["length_rows"] = r.length_rows;
  j["started"] = iso_utc(r.started);
  j["ended"] = r.ended ? nlohmann::ordered_json(iso_utc(*r.ended)) : nlohmann::ordered_json(nullptr);
  j["recorded_until"] = iso_utc(r.recorded_until);
  j["wall_s"] = seconds(r.wall_ns());
  j["rows"] = {{"recorded", r.rows}, {"last", r.last_row}};
  j["knots"] = {{"by_heads", r.knots_by_heads}, {"retried", r.knots_retried}, {"by_hand", r.knots_by_hand}};
  nlohmann::ordered_json states = nlohmann::ordered_json::object();
  for (int s = 0; s < kMachineStates; ++s) {
    const auto st = static_cast<MachineState>(s);
    states[machine_state_name(st)] = {{"s", seconds(r.state_ns[static_cast<std::size_t>(s)])},
                                      {"ns", r.state_ns[static_cast<std::size_t>(s)]},
                                      {"opcua_machinery_state", opcua_machinery_state(st)}};
  }
  j["states"] = states;
  j["yarn_knots"] = r.yarn;
  nlohmann::ordered_json faults = nlohmann::ordered_json::array();
  for (const FaultRecord& f : r.faults) {
    faults.push_back({{"at", iso_utc(f.at)},
                      {"name", f.name},
                      {"code", f.code},
                      {"acknowledged", f.cleared ? nlohmann::ordered_json(iso_utc(*f.cleared))
                                                 : nlohmann::ordered_json(nullptr)},
                      {"downtime_s", seconds(downtime_ns(r, f))}});
  }
  j["faults"] = faults;
  return j.dump(2) + "\n";
}

}  // namespace loom::record
