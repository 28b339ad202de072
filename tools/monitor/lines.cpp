// Formatting of telemetry messages as lines (see lines.hpp).
#include "lines.hpp"

#include <algorithm>
#include <cstdio>

namespace loom::monitor {

namespace {

// snprintf into a fixed buffer: the monitor prints a handful of short numbers per field.
template <typename... Args>
std::string fmt(const char* format, Args... args) {
  char buf[200];
  const int n = std::snprintf(buf, sizeof buf, format, args...);
  if (n < 0) return {};
  return std::string(buf,
                     static_cast<std::size_t>(n) < sizeof buf ? static_cast<std::size_t>(n) : sizeof buf - 1);
}

std::string head(const std::string& tag, const std::string& loom_id, std::int64_t tick, double t_s) {
  return tag + "loom=" + printable_field(loom_id) +
         fmt(" tick=%lld t=%.3fs", static_cast<long long>(tick), t_s);
}

std::string hex(std::int64_t code) {
  return fmt("0x%04llX", static_cast<unsigned long long>(code) & 0xFFFFFFFFull);
}

long long ll(std::int64_t v) {
  return static_cast<long long>(v);
}

// "loom1 t=12.345s" — the start of every event-view line.
std::string who(const std::string& loom_id, double t_s) {
  return printable_field(loom_id) + fmt(" t=%.3fs", t_s);
}

// A row the knotting heads tied (knotting mode by hand and plain weaving have no knot counts).
bool knotted_by_heads(const loomlcm::row_t& m) {
  return m.knot_s > 0.0 || m.knots_tied > 0 || m.knots_retried > 0 || m.knots_by_hand > 0;
}

std::string row_of(const loomlcm::status_t& m) {
  std::string s = fmt("row %lld", ll(m.row));
  if (m.rows_target > 0) s += fmt("/%lld", ll(m.rows_target));
  return s;
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

std::string printable_text(const std::string& s) {
  std::string out = s;
  for (char& c : out) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7f || c == '"') c = '?';
  }
  return out;
}

std::string status_line(const loomlcm::status_t& m) {
  std::string line =
      head("", m.loom_id, m.tick, m.time_s) + " state=" + printable_field(m.state) +
      fmt(" row=%lld done=%lld pick=%lld beat=%lld", ll(m.row), ll(m.rows_done), ll(m.pick), ll(m.beat)) +
      " fault=" + (m.first_fault.empty() ? std::string("none") : printable_field(m.first_fault)) +
      " fault_code=" + hex(m.first_fault_code);
  if (!m.first_fault.empty()) {
    line += " axis=" + printable_field(m.fault_axis) + " device_code=" + hex(m.fault_device_code) +
            " text=\"" + printable_text(m.fault_text) + "\"";
  }
  return line;
}

std::string axes_line(const loomlcm::axes_t& m) {
  std::string line =
      head("axes ", m.loom_id, m.tick, m.time_s) + fmt(" crank_phase=%.4frad beater=%.4frad force=%.1fN",
                                                       m.crank_phase_rad, m.beater_angle_rad, m.beat_force_n);
  for (const auto& a : m.axes) {
    line += " | " + printable_field(a.name) +
            fmt(" pos=%.6g vel=%.6g tgt=%.6g ferr=%.3g lim=%.3g eff=%.3g", a.position, a.velocity, a.target,
                a.following_error, a.following_error_limit, a.effort) +
            " drive=" + printable_field(a.drive_state);
    if (!a.unit.empty()) line += " unit=" + printable_field(a.unit);
    if (a.fault_code != 0) line += " code=" + hex(a.fault_code);
  }
  return line;
}

std::string rt_line(const loomlcm::rt_stats_t& m) {
  return head("rt ", m.loom_id, m.tick, m.time_s) +
         fmt(" overruns=%lld tick_cost_us=%.1f max_tick_cost_us=%.1f wake_p50_us=%.1f wake_p99_us=%.1f "
             "wake_max_us=%.1f",
             ll(m.overruns), static_cast<double>(m.tick_cost_ns) * 1e-3,
             static_cast<double>(m.max_tick_cost_ns) * 1e-3,
             static_cast<double>(m.wake_latency_p50_ns) * 1e-3,
             static_cast<double>(m.wake_latency_p99_ns) * 1e-3,
             static_cast<double>(m.wake_latency_max_ns) * 1e-3) +
         fmt(" dropped=%lld dropped_events=%lld backlog=%lld can_tx_dropped=%lld can_rx_errors=%lld",
             ll(m.dropped_snapshots), ll(m.dropped_events), ll(m.backlog), ll(m.can_tx_dropped),
             ll(m.can_rx_errors));
}

std::string beat_line(const loomlcm::beat_t& m) {
  return "beat loom=" + printable_field(m.loom_id) +
         fmt(" t=%.3fs row=%d index=%d x=%.4fm force=%.1fN in_band=%s", m.time_s, m.row, m.index, m.x_m,
             m.peak_force_n,
             !m.force_measured ? "unmeasured"
             : m.in_band       ? "yes"
                               : "no");
}

std::string fault_line(const loomlcm::fault_t& m) {
  return "fault loom=" + printable_field(m.loom_id) + fmt(" t=%.3fs", m.time_s) +
         " kind=" + printable_field(m.kind) + " name=" + printable_field(m.name) + " code=" + hex(m.code) +
         " axis=" + printable_field(m.axis) + " device_code=" + hex(m.device_code) +
         " state=" + printable_field(m.state) +
         fmt(" row=%d pick=%lld beat=%lld", m.row, ll(m.pick), ll(m.beat)) + " text=\"" +
         printable_text(m.text) + "\"";
}

std::string row_line(const loomlcm::row_t& m) {
  std::string line = "row loom=" + printable_field(m.loom_id) +
                     fmt(" t=%.3fs row=%d time=%.2fs shed=%.2fs pick=%.2fs beat=%.2fs beats=%d steps=%d",
                         m.time_s, m.row, m.row_s, m.shed_s, m.pick_s, m.beat_s, m.beats, m.carriage_steps);
  if (m.force_measured) {
    line += fmt(" force_min=%.1fN force_mean=%.1fN force_max=%.1fN in_band=%d/%d", m.force_min_n,
                m.force_mean_n, m.force_max_n, m.beats_in_band, m.beats);
  } else {
    line += " force_min=- force_mean=- force_max=- in_band=-";
  }
  line += fmt(" knotting=%.2fs", m.knotting_s);
  if (knotted_by_heads(m)) {
    line += fmt(" knots_tied=%d knots_retried=%d knots_by_hand=%d knot_time=%.2fs weaver_time=%.2fs",
                m.knots_tied, m.knots_retried, m.knots_by_hand, m.knot_s, m.weaver_s);
  }
  return line;
}

std::string weaver_line(const loomlcm::weaver_request_t& m) {
  return "weaver loom=" + printable_field(m.loom_id) + fmt(" t=%.3fs n=%d ask=", m.time_s, m.number) +
         printable_field(m.ask) +
         fmt(" row=%d design_row=%d knot=%d head=%d slot=%d colour=", m.row, m.design_row, m.knot, m.head,
             m.slot) +
         printable_field(m.colour) + " text=\"" + printable_text(m.text) + "\"";
}

std::string knots_line(const loomlcm::knots_t& m) {
  std::string line =
      head("knots ", m.loom_id, m.tick, m.time_s) + " state=" + printable_field(m.state) +
      fmt(" row=%d design_row=%d cycle=%d/%d cycles_done=%d tied=%lld retried=%lld by_hand=%lld", m.row,
          m.design_row, m.cycle, m.stripe, m.cycles_done, ll(m.tied), ll(m.retried), ll(m.by_hand)) +
      fmt(" row_tied=%d row_retried=%d row_by_hand=%d requests=%d ask=", m.row_tied, m.row_retried,
          m.row_by_hand, m.requests) +
      printable_field(m.ask);
  for (std::size_t h = 0; h < static_cast<std::size_t>(std::max<int>(m.heads, 0)); ++h) {
    const int knot = h < m.head_knot.size() ? m.head_knot[h] : -1;
    line += fmt(" | head%d knot=%d colour=", static_cast<int>(h), knot) +
            printable_field(h < m.head_colour.size() ? m.head_colour[h] : std::string()) + " stock=";
    if (h < m.stock.size()) {
      for (std::size_t sl = 0; sl < m.stock[h].size(); ++sl)
        line += (sl == 0 ? "" : ",") + fmt("%d", m.stock[h][sl]);
    }
  }
  return line;
}

// The next row's knots as runs of one colour, left to right ("B×2 R×2 B×4 ..."): what a weaver counts.
std::string knot_runs(const loomlcm::design_t& m) {
  const auto next = static_cast<std::size_t>(m.next_index);
  if (next >= m.knots.size()) return "-";
  std::string out;
  const auto& row = m.knots[next];
  for (std::size_t i = 0; i < row.size();) {
    std::size_t j = i;
    while (j < row.size() && row[j] == row[i]) ++j;
    const int k = row[i];
    const std::string code =
        k >= 0 && k < m.n_colours ? printable_field(m.code[static_cast<std::size_t>(k)]) : "?";
    out += (out.empty() ? "" : " ") + code + fmt("x%d", static_cast<int>(j - i));
    i = j;
  }
  return out;
}

std::string design_line(const loomlcm::design_t& m) {
  return "design loom=" + printable_field(m.loom_id) + " name=" + printable_field(m.name) +
         fmt(" next_row=%d/%d repeat=%d rows_done=%lld width=%d knots=", m.next_row, m.height, m.repeat,
             ll(m.rows_done), m.width) +
         knot_runs(m);
}

// ---- the event view ----

std::vector<std::string> EventView::on_status(const loomlcm::status_t& m) {
  std::vector<std::string> out;
  Loom& l = looms_[m.loom_id];
  if (m.tick < l.last_tick) {
    out.push_back(who(m.loom_id, m.time_s) + " (loop restarted)");
    l = Loom{};
  }
  l.last_tick = m.tick;
  if (m.state != l.state) {
    std::string line = who(m.loom_id, m.time_s) + " state " +
                       (l.state.empty() ? "-" : printable_field(l.state)) + " -> " +
                       printable_field(m.state) + ", " + row_of(m);
    if (!m.first_fault.empty()) {
      line += ", fault " + printable_field(m.first_fault) + " (" + hex(m.first_fault_code) + ")";
    }
    out.push_back(line);
    l.state = m.state;
    l.last_status_t = m.time_s;
    return out;
  }
  if (m.time_s - l.last_status_t >= status_every_s_) {
    l.last_status_t = m.time_s;
    std::string line = who(m.loom_id, m.time_s) + "   " + printable_field(m.state) + ", " + row_of(m) +
                       fmt(", picks %lld, beats %lld", ll(m.pick), ll(m.beat));
    if (!m.first_fault.empty()) line += ", fault " + printable_field(m.first_fault);
    if (l.rt_seen && (l.overruns > 0 || l.dropped > 0 || l.dropped_events > 0 || l.can_tx_dropped > 0 ||
                      l.can_rx_errors > 0)) {
      line += fmt(" [overruns %lld, dropped %lld+%lld, can tx drops %lld, rx errors %lld]", ll(l.overruns),
                  ll(l.dropped), ll(l.dropped_events), ll(l.can_tx_dropped), ll(l.can_rx_errors));
    }
    out.push_back(line);
  }
  return out;
}

std::vector<std::string> EventView::on_beat(const loomlcm::beat_t& m) {
  if (!show_beats_) return {};
  std::string line = who(m.loom_id, m.time_s) + fmt(" beat  row %d #%d", m.row, m.index + 1);
  if (m.beats_per_row > 0) line += fmt("/%d", m.beats_per_row);
  line += fmt(" at x=%.3f m: ", m.x_m);
  if (m.force_measured) {
    line += fmt("%.1f N %s", m.peak_force_n,
                m.in_band ? "in band" : (m.peak_force_n < m.band_min_n ? "BELOW band" : "ABOVE band"));
    line += fmt(" %.0f-%.0f N", m.band_min_n, m.band_max_n);
  } else {
    line += "force not measured";
  }
  return {line};
}

std::vector<std::string> EventView::on_row(const loomlcm::row_t& m) {
  std::string line =
      who(m.loom_id, m.time_s) + fmt(" row %d done in %.2f s (shed %.2f, pick %.2f, beat %.2f s), %d beats",
                                     m.row, m.row_s, m.shed_s, m.pick_s, m.beat_s, m.beats);
  if (m.force_measured) {
    line += fmt(", force min/mean/max %.1f/%.1f/%.1f N, %d/%d in band", m.force_min_n, m.force_mean_n,
                m.force_max_n, m.beats_in_band, m.beats);
  }
  if (m.knotting_s > 0.0) line += fmt(", knotted in %.1f s before it", m.knotting_s);
  if (knotted_by_heads(m)) {
    line += fmt(", knots %d tied, %d retried, %d by hand (heads %.1f s", m.knots_tied, m.knots_retried,
                m.knots_by_hand, m.knot_s);
    line += m.weaver_s > 0.0 ? fmt(", weaver %.1f s)", m.weaver_s) : std::string(")");
  }
  return {line};
}

std::vector<std::string> EventView::on_weaver(const loomlcm::weaver_request_t& m) {
  return {who(m.loom_id, m.time_s) + " WEAVER " + printable_field(m.ask) + ": " + printable_text(m.text)};
}

std::vector<std::string> EventView::on_fault(const loomlcm::fault_t& m) {
  std::string line =
      who(m.loom_id, m.time_s) + " FAULT " + printable_field(m.name) + " (" + hex(m.code) + ")";
  if (!m.axis.empty()) line += " axis " + printable_field(m.axis);
  if (m.device_code != 0) line += " device code " + hex(m.device_code);
  line += ": " + printable_text(m.text) + " [" + printable_field(m.kind) + "; in " +
          printable_field(m.state) + fmt(", row %d, picks %lld, beats %lld]", m.row, ll(m.pick), ll(m.beat));
  return {line};
}

std::vector<std::string> EventView::on_rt(const loomlcm::rt_stats_t& m) {
  Loom& l = looms_[m.loom_id];
  l.rt_seen = true;
  l.overruns = m.overruns;
  l.dropped = m.dropped_snapshots;
  l.dropped_events = m.dropped_events;
  l.can_tx_dropped = m.can_tx_dropped;
  l.can_rx_errors = m.can_rx_errors;
  return {};
}

std::vector<std::string> EventView::on_design(const loomlcm::design_t& m) {
  Loom& l = looms_[m.loom_id];
  if (l.design_rows_done == m.rows_done) return {};
  l.design_rows_done = m.rows_done;
  return {printable_field(m.loom_id) + " knot row " + fmt("%d/%d", m.next_row, m.height) +
          (m.repeat > 1 ? fmt(" (repeat %d)", m.repeat) : std::string()) + " of " + printable_field(m.name) +
          ": " + knot_runs(m)};
}

}  // namespace loom::monitor
