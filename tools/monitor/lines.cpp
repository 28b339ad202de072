// Formatting of STATUS / AXES / RT messages as single key=value lines (see lines.hpp).
#include "lines.hpp"

#include <cstdio>

namespace loom::monitor {

namespace {

// snprintf into a fixed buffer: the monitor prints a handful of short numbers per field.
template <typename... Args>
std::string fmt(const char* format, Args... args) {
  char buf[160];
  const int n = std::snprintf(buf, sizeof buf, format, args...);
  if (n < 0) return {};
  return std::string(buf,
                     static_cast<std::size_t>(n) < sizeof buf ? static_cast<std::size_t>(n) : sizeof buf - 1);
}

std::string head(const std::string& tag, const std::string& loom_id, std::int64_t tick, double t_s) {
  return tag + "loom=" + printable_field(loom_id) +
         fmt(" tick=%lld t=%.3fs", static_cast<long long>(tick), t_s);
}

}  // namespace

std::string printable_field(const std::string& s) {
  if (s.empty()) return "-";
  std::string out = s;
  for (char& c : out) {
    const auto u = static_cast<unsigned char>(c);
    if (u <= 0x20 || u >= 0x7f) c = '?';
  }
  return out;
}

std::string status_line(const loomlcm::status_t& m) {
  return head("", m.loom_id, m.tick, m.time_s) + " state=" + printable_field(m.state) +
         fmt(" row=%lld pick=%lld beat=%lld", static_cast<long long>(m.row), static_cast<long long>(m.pick),
             static_cast<long long>(m.beat)) +
         " fault=" + (m.first_fault.empty() ? std::string("none") : printable_field(m.first_fault)) +
         fmt(" fault_code=%d", static_cast<int>(m.first_fault_code));
}

std::string axes_line(const loomlcm::axes_t& m) {
  std::string line =
      head("axes ", m.loom_id, m.tick, m.time_s) + fmt(" crank_phase=%.4frad beater=%.4frad force=%.1fN",
                                                       m.crank_phase_rad, m.beater_angle_rad, m.beat_force_n);
  for (const auto& a : m.axes) {
    line += " | " + printable_field(a.name) +
            fmt(" pos=%.6g vel=%.6g tgt=%.6g ferr=%.3g eff=%.3g", a.position, a.velocity, a.target,
                a.following_error, a.effort) +
            " drive=" + printable_field(a.drive_state);
  }
  return line;
}

std::string rt_line(const loomlcm::rt_stats_t& m) {
  return head("rt ", m.loom_id, m.tick, m.time_s) +
         fmt(" overruns=%lld tick_cost_us=%.1f max_tick_cost_us=%.1f dropped=%lld backlog=%lld",
             static_cast<long long>(m.overruns), static_cast<double>(m.tick_cost_ns) * 1e-3,
             static_cast<double>(m.max_tick_cost_ns) * 1e-3, static_cast<long long>(m.dropped_snapshots),
             static_cast<long long>(m.backlog));
}

}  // namespace loom::monitor
