// The panel's bounded model of the hall (see hall.hpp).
#include "hall.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace loom::panel {

std::string json_text(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace {

using nlohmann::json;

// JSON has no NaN/inf: a non-finite number from the wire is sent as null, never as invalid JSON.
json num(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

std::string hex(std::int64_t code) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04llX", static_cast<unsigned long long>(code) & 0xFFFFFFFFull);
  return buf;
}

json status_json(const loomlcm::status_t& m) {
  json j = {{"tick", m.tick},  {"time_s", num(m.time_s)},  {"state", m.state},
            {"row", m.row},    {"rows_done", m.rows_done}, {"rows_target", m.rows_target},
            {"picks", m.pick}, {"beats", m.beat},          {"beats_per_row", m.beats_per_row}};
  if (!m.first_fault.empty()) {
    j["fault"] = {{"name", m.first_fault},     {"code", hex(m.first_fault_code)},
                  {"axis", m.fault_axis},      {"device_code", hex(m.fault_device_code)},
                  {"text", m.fault_text},      {"time_s", num(m.fault_time_s)},
                  {"stopped_by", m.stopped_by}};
  } else {
    j["fault"] = nullptr;
  }
  return j;
}

json axes_json(const loomlcm::axes_t& m) {
  json axes = json::array();
  for (const auto& a : m.axes) {
    axes.push_back({{"name", a.name},
                    {"unit", a.unit},
                    {"position", num(a.position)},
                    {"velocity", num(a.velocity)},
                    {"target", num(a.target)},
                    {"following_error", num(a.following_error)},
                    {"following_error_limit", num(a.following_error_limit)},
                    {"effort", num(a.effort)},
                    {"drive_state", a.drive_state},
                    {"fault_code", a.fault_code != 0 ? json(hex(a.fault_code)) : json(nullptr)}});
  }
  return {{"time_s", num(m.time_s)},
          {"crank_phase_rad", num(m.crank_phase_rad)},
          {"beater_angle_rad", num(m.beater_angle_rad)},
          {"beat_force_n", m.beat_force_valid ? num(m.beat_force_n) : json(nullptr)},
          {"axes", axes}};
}

json rt_json(const loomlcm::rt_stats_t& m) {
  return {{"period_ns", m.period_ns},
          {"overruns", m.overruns},
          {"tick_cost_ns", m.tick_cost_ns},
          {"max_tick_cost_ns", m.max_tick_cost_ns},
          {"wake_latency_p50_ns", m.wake_latency_p50_ns},
          {"wake_latency_p99_ns", m.wake_latency_p99_ns},
          {"wake_latency_max_ns", m.wake_latency_max_ns},
          {"dropped_snapshots", m.dropped_snapshots},
          {"dropped_events", m.dropped_events},
          {"backlog", m.backlog},
          {"can_tx_dropped", m.can_tx_dropped},
          {"can_rx_errors", m.can_rx_errors}};
}

json row_json(const loomlcm::row_t& m) {
  json j = {{"row", m.row},
            {"time_s", num(m.row_s)},
            {"shed_s", num(m.shed_s)},
            {"pick_s", num(m.pick_s)},
            {"beat_s", num(m.beat_s)},
            {"knotting_s", num(m.knotting_s)},
            {"knot_s", num(m.knot_s)},
            {"weaver_s", num(m.weaver_s)},
            {"knots_tied", m.knots_tied},
            {"knots_retried", m.knots_retried},
            {"knots_by_hand", m.knots_by_hand},
            {"beats", m.beats},
            {"carriage_steps", m.carriage_steps},
            {"beats_in_band", m.beats_in_band}};
  if (m.force_measured) {
    j["force"] = {{"min", num(m.force_min_n)}, {"mean", num(m.force_mean_n)}, {"max", num(m.force_max_n)}};
  } else {
    j["force"] = nullptr;
  }
  return j;
}

std::string rgb_hex(std::int32_t rgb) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%06x", static_cast<unsigned>(rgb) & 0xFFFFFFu);
  return buf;
}

// The design row to knot next and its neighbours, with the palette, as the page draws them. Indices
// outside the palette (a corrupt message) are sent as null rather than trusted.
json design_json(const loomlcm::design_t& m) {
  json palette = json::array();
  for (int i = 0; i < m.n_colours; ++i) {
    palette.push_back({{"code", m.code[static_cast<std::size_t>(i)]},
                       {"name", m.colour_name[static_cast<std::size_t>(i)]},
                       {"rgb", rgb_hex(m.rgb[static_cast<std::size_t>(i)])}});
  }
  json rows = json::array();
  for (int r = 0; r < m.n_rows; ++r) {
    json knots = json::array();
    for (std::int16_t k : m.knots[static_cast<std::size_t>(r)])
      knots.push_back(k >= 0 && k < m.n_colours ? json(k) : json(nullptr));
    rows.push_back(
        {{"row", m.row_number[static_cast<std::size_t>(r)]}, {"next", r == m.next_index}, {"knots", knots}});
  }
  return {{"name", m.name},         {"width", m.width},   {"height", m.height}, {"rows_done", m.rows_done},
          {"next_row", m.next_row}, {"repeat", m.repeat}, {"palette", palette}, {"rows", rows}};
}

json weaver_json(const loomlcm::weaver_request_t& m) {
  return {{"time_s", num(m.time_s)},    {"number", m.number}, {"ask", m.ask},   {"row", m.row},
          {"design_row", m.design_row}, {"knot", m.knot},     {"head", m.head}, {"slot", m.slot},
          {"colour", m.colour},         {"text", m.text}};
}

json fault_json(const loomlcm::fault_t& m) {
  return {
      {"time_s", num(m.time_s)}, {"utime", m.utime}, {"kind", m.kind},  {"name", m.name},
      {"code", hex(m.code)},     {"text", m.text},   {"axis", m.axis},  {"device_code", hex(m.device_code)},
      {"state", m.state},        {"row", m.row},     {"picks", m.pick}, {"beats", m.beat}};
}

}  // namespace

Hall::Hall(HallLimits limits, std::function<std::int64_t()> wall_now_us)
    : limits_(limits), wall_now_us_(std::move(wall_now_us)) {
  if (!wall_now_us_) {
    wall_now_us_ = [] {
      return std::chrono::duration_cast<std::chrono::microseconds>(
                 std::chrono::system_clock::now().time_since_epoch())
          .count();
    };
  }
}

Hall::Loom* Hall::loom(const std::string& id, std::int64_t utime) {
  if (limits_.replay_after_s <= 0.0) return loom(id);
  const double age_s = static_cast<double>(wall_now_us_() - utime) * 1e-6;
  if (!(age_s > limits_.replay_after_s)) return loom(id);
  Loom* l = loom(id + kReplaySuffix);
  if (l != nullptr) {
    l->replay = true;
    l->recorded_s_ago = age_s;
  }
  return l;
}

Hall::Loom* Hall::loom(const std::string& id) {
  auto it = looms_.find(id);
  if (it == looms_.end()) {
    if (looms_.size() >= limits_.looms) {
      ++ignored_;
      return nullptr;
    }
    it = looms_.emplace(id, Loom{}).first;
  }
  it->second.heard = Clock::now();
  return &it->second;
}

void Hall::changed() {
  ++version_;
  cv_.notify_all();
}

void Hall::on_status(const loomlcm::status_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    if (l->status &&
        m.tick < l->status->tick) {  // the loop restarted: what was kept belongs to the previous run
      const Loom keep = *l;
      *l = Loom{};
      l->heard = keep.heard;
      l->replay = keep.replay;
      l->recorded_s_ago = keep.recorded_s_ago;
    }
    l->status = m;
    changed();
  }
}

void Hall::on_axes(const loomlcm::axes_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    l->axes = m;
    add_scope_sample(*l, m);
    changed();
  }
}

void Hall::add_scope_sample(Loom& l, const loomlcm::axes_t& m) const {
  if (!std::isfinite(m.time_s)) return;
  const std::size_t n = std::min<std::size_t>(m.axes.size(), 32);
  bool same = l.scope_names.size() == n;
  for (std::size_t i = 0; same && i < n; ++i) same = l.scope_names[i] == m.axes[i].name;
  // Another set of axes, or loop time going back (the loop restarted): the strip starts afresh.
  if (!same || (!l.scope.empty() && m.time_s < l.scope.back().time_s)) {
    l.scope.clear();
    l.scope_names.clear();
    for (std::size_t i = 0; i < n; ++i) l.scope_names.push_back(m.axes[i].name);
  }
  ScopeSample s;
  s.time_s = m.time_s;
  s.axes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = m.axes[i];
    s.axes.push_back({static_cast<float>(a.position), static_cast<float>(a.velocity),
                      static_cast<float>(a.following_error)});
  }
  l.scope.push_back(std::move(s));
  while (l.scope.size() > limits_.scope_samples ||
         (l.scope.size() > 1 && l.scope.back().time_s - l.scope.front().time_s > limits_.scope_window_s)) {
    l.scope.pop_front();
  }
}

void Hall::on_rt(const loomlcm::rt_stats_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    l->rt = m;
    changed();
  }
}

void Hall::on_beat(const loomlcm::beat_t& m) {
  std::lock_guard lock(mu_);
  Loom* l = loom(m.loom_id, m.utime);
  if (l == nullptr) return;
  if (m.row != l->current.row) {
    // A new row: the one before becomes "previous" (only if it is the row just before).
    l->previous = m.row == l->current.row + 1 ? std::move(l->current) : BeatRow{};
    l->current = BeatRow{m.row, {}};
  }
  if (l->current.beats.size() < limits_.beats_per_row) {
    l->current.beats.push_back({m.index, m.x_m, m.peak_force_n, m.force_measured != 0, m.in_band != 0});
  }
  l->band_min_n = m.band_min_n;
  l->band_max_n = m.band_max_n;
  ++l->beats_seen;
  if (m.in_band) ++l->beats_in_band;
  changed();
}

void Hall::on_fault(const loomlcm::fault_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    l->faults.push_back(m);
    while (l->faults.size() > limits_.faults_kept) l->faults.pop_front();
    ++l->faults_seen;
    changed();
  }
}

void Hall::on_row(const loomlcm::row_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    l->rows.push_back(m);
    while (l->rows.size() > std::max(limits_.rows_kept, limits_.rows_report)) l->rows.pop_front();
    changed();
  }
}

void Hall::on_design(const loomlcm::design_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    // Only a new row is a change worth pushing to every page; the periodic repeat just refreshes it.
    const bool moved = !l->design || l->design->rows_done != m.rows_done || l->design->name != m.name;
    l->design = m;
    if (moved) changed();
  }
}

void Hall::on_knots(const loomlcm::knots_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    l->knots = m;
    changed();
  }
}

namespace {
// The job and its queue as the page shows them; counts are not trusted beyond the arrays.
json job_json(const loomlcm::job_t& m, std::size_t jobs_listed) {
  const std::size_t heads = std::min<std::size_t>(m.heads > 0 ? static_cast<std::size_t>(m.heads) : 0,
                                                  std::min<std::size_t>(m.stock.size(), 12));
  const std::size_t slots = std::min<std::size_t>(m.slots > 0 ? static_cast<std::size_t>(m.slots) : 0,
                                                  std::min<std::size_t>(m.slot_colour.size(), 16));
  json stock = json::array();
  for (std::size_t h = 0; h < heads; ++h) {
    json levels = json::array();
    for (std::size_t s = 0; s < slots && s < m.stock[h].size(); ++s) levels.push_back(m.stock[h][s]);
    stock.push_back(levels);
  }
  json slot_colours = json::array();
  for (std::size_t s = 0; s < slots; ++s) slot_colours.push_back(m.slot_colour[s]);
  const std::size_t n = std::min({m.n_jobs > 0 ? static_cast<std::size_t>(m.n_jobs) : std::size_t{0},
                                  m.queue_id.size(), m.queue_design.size(), m.queue_state.size(),
                                  m.queue_rows_done.size(), m.queue_rows_total.size()});
  const std::size_t first = n > jobs_listed ? n - jobs_listed : 0;
  json queue = json::array();
  for (std::size_t i = first; i < n; ++i) {
    queue.push_back({{"id", m.queue_id[i]},
                     {"design", m.queue_design[i]},
                     {"state", m.queue_state[i]},
                     {"rows_done", m.queue_rows_done[i]},
                     {"rows", m.queue_rows_total[i]}});
  }
  return {{"id", m.job_id},
          {"state", m.state},
          {"design", m.design_name},
          {"hash", m.design_hash},
          {"width", m.width},
          {"design_rows", m.design_rows},
          {"rows_done", m.rows_done},
          {"rows", m.rows_total},
          {"stripe", m.stripe},
          {"cycles_done", m.cycles_done},
          {"row_mean_s", m.row_mean_s >= 0 ? num(m.row_mean_s) : json(nullptr)},
          {"eta_s", m.eta_s >= 0 ? num(m.eta_s) : json(nullptr)},
          {"knots_per_slot", m.knots_per_slot},
          {"slot_colours", slot_colours},
          {"stock", stock},
          {"queue", queue},
          {"queue_cut", first}};
}
}  // namespace

void Hall::on_job(const loomlcm::job_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    l->job = m;
    changed();
  }
}

void Hall::on_carpet(const loomlcm::carpet_t& m) {
  std::lock_guard lock(mu_);
  Loom* l = loom(m.loom_id, m.utime);
  if (l == nullptr) return;
  // A band that contradicts itself (a spoofed or corrupt CARPET) is dropped whole.
  if (m.width <= 0 || m.height <= 0 || m.n_rows <= 0 || m.first_row < 0 ||
      m.first_row + m.n_rows > m.height || static_cast<std::int64_t>(m.n_rows) * m.width != m.n_knots ||
      m.knots.size() != static_cast<std::size_t>(m.n_knots) || m.code.size() != m.rgb.size() ||
      m.code.size() != static_cast<std::size_t>(std::max<std::int16_t>(m.n_colours, 0))) {
    return;
  }
  Carpet& c = l->carpet;
  const auto knots = static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height);
  if (c.hash != m.design_hash || c.job_id != m.job_id || c.width != m.width || c.height != m.height) {
    c = Carpet{};
    c.hash = m.design_hash;
    c.name = m.design_name;
    c.job_id = m.job_id;
    c.width = m.width;
    c.height = m.height;
    c.codes = m.code;
    c.rgb = m.rgb;
    c.too_big = knots > limits_.carpet_knots;
    if (!c.too_big) {
      c.knots.assign(knots, 0xFF);
      c.have.assign(static_cast<std::size_t>(m.height), false);
    }
    changed();
  }
  if (c.too_big) return;
  std::size_t fresh = 0;
  for (std::int32_t r = 0; r < m.n_rows; ++r) {
    const auto row = static_cast<std::size_t>(m.first_row + r);
    const auto w = static_cast<std::size_t>(c.width);
    std::copy_n(m.knots.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(r) * w), w,
                c.knots.begin() + static_cast<std::ptrdiff_t>(row * w));
    if (!c.have[row]) {
      c.have[row] = true;
      ++fresh;
    }
  }
  c.rows_heard += fresh;
  if (fresh > 0) changed();  // the periodic repeat of a map already whole pushes nothing
}

std::optional<json> Hall::carpet_json(const std::string& id) const {
  std::lock_guard lock(mu_);
  const auto it = looms_.find(id);
  if (it == looms_.end() || it->second.carpet.hash.empty()) return std::nullopt;
  const Carpet& c = it->second.carpet;
  json palette = json::array();
  for (std::size_t i = 0; i < c.codes.size(); ++i)
    palette.push_back({{"code", c.codes[i]}, {"rgb", rgb_hex(c.rgb[i])}});
  static const char kHex[] = "0123456789abcdef";
  std::string knots;
  knots.reserve(c.knots.size() * 2);
  for (std::uint8_t k : c.knots) {
    knots += kHex[k >> 4];
    knots += kHex[k & 15];
  }
  return json{
      {"loom", id},           {"job", c.job_id},    {"hash", c.hash},     {"design", c.name},
      {"width", c.width},     {"height", c.height}, {"palette", palette}, {"rows_heard", c.rows_heard},
      {"too_big", c.too_big}, {"knots", knots}};
}

void Hall::on_weaver(const loomlcm::weaver_request_t& m) {
  std::lock_guard lock(mu_);
  if (Loom* l = loom(m.loom_id, m.utime)) {
    l->weaver.push_back(m);
    while (l->weaver.size() > limits_.weaver_requests_kept) l->weaver.pop_front();
    changed();
  }
}

// The row the heads tie, knot by knot, as the page draws it. The message's counts are not trusted
// beyond its arrays (a spoofed or corrupt KNOTS): heads at most 12, slots 16, knots the limit.
json Hall::knots_json(const loomlcm::knots_t& m) const {
  const auto count = [](std::int64_t n, std::size_t have, std::size_t cap) {
    return std::min<std::size_t>({n > 0 ? static_cast<std::size_t>(n) : 0, have, cap});
  };
  const std::size_t heads = count(
      m.heads, std::min({m.head_knot.size(), m.head_slot.size(), m.head_colour.size(), m.stock.size()}), 12);
  const std::size_t slots = count(m.slots, m.slot_colour.size(), 16);
  const std::size_t knots = count(m.knots_per_row, m.knot_slot.size(), limits_.knots_per_row);
  json slot_colours = json::array();
  for (std::size_t s = 0; s < slots; ++s) slot_colours.push_back(m.slot_colour[s]);
  json row = json::array();
  for (std::size_t k = 0; k < knots; ++k) {
    const int s = m.knot_slot[k];
    row.push_back(s >= 0 && static_cast<std::size_t>(s) < slots ? json(s) : json(nullptr));
  }
  json hs = json::array();
  for (std::size_t h = 0; h < heads; ++h) {
    json stock = json::array();
    for (std::size_t s = 0; s < slots && s < m.stock[h].size(); ++s) stock.push_back(m.stock[h][s]);
    hs.push_back({{"head", h},
                  {"knot", m.head_knot[h]},
                  {"slot", m.head_slot[h]},
                  {"colour", m.head_colour[h]},
                  {"stock", stock}});
  }
  json ask = m.ask.empty() ? json(nullptr)
                           : json{{"ask", m.ask},
                                  {"knot", m.ask_knot},
                                  {"head", m.ask_head},
                                  {"slot", m.ask_slot},
                                  {"text", m.ask_text}};
  return {{"time_s", num(m.time_s)},
          {"state", m.state},
          {"knotting", m.knotting != 0},
          {"row", m.row},
          {"design_row", m.design_row},
          {"heads", hs},
          {"stripe", m.stripe},
          {"knots_per_row", m.knots_per_row},
          {"cut", knots < static_cast<std::size_t>(std::max<int>(m.knots_per_row, 0))},
          {"knots_per_slot", m.knots_per_slot},
          {"cycle", m.cycle},
          {"cycles_done", m.cycles_done},
          {"tied", m.tied},
          {"retried", m.retried},
          {"by_hand", m.by_hand},
          {"row_tied", m.row_tied},
          {"row_retried", m.row_retried},
          {"row_by_hand", m.row_by_hand},
          {"requests", m.requests},
          {"slot_colours", slot_colours},
          {"row_slots", row},
          {"request", ask}};
}

json Hall::summary(const std::string& id, const Loom& l, Clock::time_point now) {
  json j = {{"id", id},
            {"loom", l.replay ? id.substr(0, id.size() - std::char_traits<char>::length(kReplaySuffix)) : id},
            {"replay", l.replay},
            {"recorded_s_ago", l.replay ? num(l.recorded_s_ago) : json(nullptr)},
            {"heard_s_ago", std::chrono::duration<double>(now - l.heard).count()},
            {"beats_seen", l.beats_seen},
            {"beats_in_band", l.beats_in_band},
            {"faults_seen", l.faults_seen}};
  j["status"] = l.status ? status_json(*l.status) : json(nullptr);
  j["last_row"] = l.rows.empty() ? json(nullptr) : row_json(l.rows.back());
  j["design"] = l.design ? json{{"name", l.design->name},
                                {"next_row", l.design->next_row},
                                {"height", l.design->height},
                                {"repeat", l.design->repeat}}
                         : json(nullptr);
  return j;
}

json Hall::hall_json() const {
  std::lock_guard lock(mu_);
  const auto now = Clock::now();
  json looms = json::array();
  for (const auto& [id, l] : looms_) looms.push_back(summary(id, l, now));
  return {{"version", version_}, {"looms", looms}, {"ignored_looms", ignored_}};
}

std::optional<json> Hall::loom_json(const std::string& id) const {
  std::lock_guard lock(mu_);
  const auto it = looms_.find(id);
  if (it == looms_.end()) return std::nullopt;
  const Loom& l = it->second;
  json j = summary(id, l, Clock::now());
  j["version"] = version_;
  j["axes"] = l.axes ? axes_json(*l.axes) : json(nullptr);
  j["rt"] = l.rt ? rt_json(*l.rt) : json(nullptr);
  j["band"] = {{"min_n", num(l.band_min_n)}, {"max_n", num(l.band_max_n)}};
  const auto beats = [](const BeatRow& r) {
    json b = json::array();
    for (const auto& x : r.beats) {
      b.push_back({{"index", x.index},
                   {"x_m", num(x.x_m)},
                   {"force_n", x.measured ? num(x.force_n) : json(nullptr)},
                   {"in_band", x.in_band}});
    }
    return json{{"row", r.row}, {"beats", b}};
  };
  j["current_row"] = beats(l.current);
  j["previous_row"] = beats(l.previous);
  json rows = json::array();
  const std::size_t first = l.rows.size() > limits_.rows_kept ? l.rows.size() - limits_.rows_kept : 0;
  for (std::size_t i = first; i < l.rows.size(); ++i) rows.push_back(row_json(l.rows[i]));
  j["rows"] = rows;
  json faults = json::array();
  for (const auto& f : l.faults) faults.push_back(fault_json(f));
  j["faults"] = faults;
  j["design"] = l.design ? design_json(*l.design) : json(nullptr);
  j["knots"] = l.knots ? knots_json(*l.knots) : json(nullptr);
  j["job"] = l.job ? job_json(*l.job, limits_.jobs_listed) : json(nullptr);
  // The knot map itself is fetched apart (/api/loom/<id>/carpet) when this says it changed.
  j["carpet"] = l.carpet.hash.empty() ? json(nullptr)
                                      : json{{"job", l.carpet.job_id},
                                             {"hash", l.carpet.hash},
                                             {"height", l.carpet.height},
                                             {"rows_heard", l.carpet.rows_heard},
                                             {"too_big", l.carpet.too_big}};
  json weaver = json::array();
  for (const auto& w : l.weaver) weaver.push_back(weaver_json(w));
  j["weaver_requests"] = weaver;
  j["controls"] = false;  // the HTTP side says whether it may act on this loom (main.cpp)
  return j;
}

namespace {
// A number for the CSV: fixed notation with 6 decimals (a spreadsheet reads it; no 1e-05), empty when not
// finite.
std::string csv_num(double v) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}
std::string utc_of(std::int64_t utime) {
  if (utime <= 0) return "";
  const std::time_t t = static_cast<std::time_t>(utime / 1'000'000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}
}  // namespace

std::optional<std::string> Hall::rows_csv(const std::string& id) const {
  std::lock_guard lock(mu_);
  const auto it = looms_.find(id);
  if (it == looms_.end()) return std::nullopt;
  std::string out =
      "utc,loop_time_s,row,row_s,shed_s,pick_s,beat_s,beats,carriage_steps,force_min_n,force_mean_n,force_"
      "max_n,"
      "beats_in_band,band_min_n,band_max_n,knotting_s,knot_s,weaver_s,knots_tied,knots_retried,knots_by_"
      "hand\n";
  for (const loomlcm::row_t& r : it->second.rows) {
    const bool f = r.force_measured;
    out += utc_of(r.utime) + "," + csv_num(r.time_s) + "," + std::to_string(r.row) + "," + csv_num(r.row_s) +
           "," + csv_num(r.shed_s) + "," + csv_num(r.pick_s) + "," + csv_num(r.beat_s) + "," +
           std::to_string(r.beats) + "," + std::to_string(r.carriage_steps) + "," +
           (f ? csv_num(r.force_min_n) : "") + "," + (f ? csv_num(r.force_mean_n) : "") + "," +
           (f ? csv_num(r.force_max_n) : "") + "," + std::to_string(r.beats_in_band) + "," +
           csv_num(r.band_min_n) + "," + csv_num(r.band_max_n) + "," + csv_num(r.knotting_s) + "," +
           csv_num(r.knot_s) + "," + csv_num(r.weaver_s) + "," + std::to_string(r.knots_tied) + "," +
           std::to_string(r.knots_retried) + "," + std::to_string(r.knots_by_hand) + "\n";
  }
  return out;
}

std::optional<json> Hall::scope_json(const std::string& id, const std::string& axis) const {
  std::lock_guard lock(mu_);
  const auto it = looms_.find(id);
  if (it == looms_.end()) return std::nullopt;
  const Loom& l = it->second;
  const auto at = std::find(l.scope_names.begin(), l.scope_names.end(), axis);
  json t = json::array(), pos = json::array(), vel = json::array(), fe = json::array();
  if (at != l.scope_names.end()) {
    const auto i = static_cast<std::size_t>(at - l.scope_names.begin());
    for (const ScopeSample& s : l.scope) {
      t.push_back(num(s.time_s));
      pos.push_back(num(static_cast<double>(s.axes[i][0])));
      vel.push_back(num(static_cast<double>(s.axes[i][1])));
      fe.push_back(num(static_cast<double>(s.axes[i][2])));
    }
  }
  return json{
      {"loom", id}, {"axis", axis},    {"axes", l.scope_names}, {"window_s", num(limits_.scope_window_s)},
      {"t", t},     {"position", pos}, {"velocity", vel},       {"following_error", fe}};
}

std::uint64_t Hall::version() const {
  std::lock_guard lock(mu_);
  return version_;
}

std::uint64_t Hall::wait_for_change(std::uint64_t seen, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, timeout, [&] { return version_ != seen; });
  return version_;
}

std::size_t Hall::ignored_looms() const {
  std::lock_guard lock(mu_);
  return ignored_;
}

}  // namespace loom::panel
