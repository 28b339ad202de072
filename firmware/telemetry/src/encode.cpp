// Field-by-field mapping from the RT snapshot to the three LCM messages (STATUS, AXES, RT).
#include "loom/telemetry/encode.hpp"

#include <algorithm>
#include <limits>

#include "loom/hal/types.hpp"
#include "loom/sequencer/faults.hpp"
#include "loom/sequencer/knot_program.hpp"
#include "loom/sequencer/row_knotter.hpp"
#include "loom/sequencer/sequencer.hpp"

namespace loom::telemetry {

namespace {

std::int64_t to_i64(std::uint64_t v) noexcept {
  return static_cast<std::int64_t>(
      std::min<std::uint64_t>(v, static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())));
}

double seconds(hal::Tick ticks, std::int64_t period_ns) noexcept {
  return static_cast<double>(ticks) * static_cast<double>(period_ns) * 1e-9;
}

std::string axis_or_empty(const hal::AxisLayout& axes, int axis) {
  return axis >= 0 && static_cast<std::size_t>(axis) < axes.count ? axes.name(static_cast<std::size_t>(axis))
                                                                  : std::string();
}

}  // namespace

double loop_time_s(const Snapshot& s) noexcept {
  return seconds(s.tick, s.period_ns);
}

namespace {
// A fault value from the ring (the sequencer's enum, carried as a byte); the table's lookups answer
// "?" for a value outside it.
sequencer::Fault fault_of(std::uint8_t v) noexcept {
  return static_cast<sequencer::Fault>(v);
}
// A state from the ring (the sequencer's enum as a byte): its name, "?" outside the enum.
std::string state_of(std::uint8_t v) {
  return sequencer::state_name(static_cast<sequencer::State>(v));
}
// The operator text, naming the safety sensor a fault is about ("...: shuttle_at_right").
std::string with_sensor(std::string text, std::int8_t sensor) {
  if (sensor >= 0 && sensor < static_cast<std::int8_t>(hal::kSafetySensorCount)) {
    text += std::string(": ") + hal::safety_sensor_name(static_cast<hal::SafetySensor>(sensor));
  }
  return text;
}
}  // namespace

loomlcm::status_t to_status(const Snapshot& s, const std::string& loom_id, std::int64_t utime,
                            const hal::AxisLayout& axes) {
  loomlcm::status_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = s.tick;
  m.time_s = loop_time_s(s);
  m.period_ns = s.period_ns;
  m.state = state_of(s.state);
  m.row = s.row_in_progress;
  m.rows_done = s.row;
  m.rows_target = s.rows_target;
  m.pick = s.pick;
  m.beat = s.beat;
  m.beats_per_row = s.beats_per_row;
  const bool faulted = s.first_fault != 0;
  m.first_fault = faulted ? sequencer::fault_name(fault_of(s.first_fault)) : "";
  m.first_fault_code = s.first_fault_code;
  m.fault_axis = faulted ? axis_or_empty(axes, s.fault_axis) : std::string();
  m.fault_device_code = faulted ? s.fault_device_code : 0;
  m.fault_text =
      faulted ? with_sensor(sequencer::fault_text(fault_of(s.first_fault)), s.fault_sensor) : std::string();
  m.fault_time_s = faulted && s.fault_tick >= 0 ? seconds(s.fault_tick, s.period_ns) : 0.0;
  m.stopped_by = faulted ? sequencer::fault_name(fault_of(s.stopped_by)) : "";
  m.outputs = s.outputs;
  m.inputs = s.inputs;
  m.inputs_2 = s.inputs_2;
  return m;
}

loomlcm::axes_t to_axes(const Snapshot& s, const std::string& loom_id, std::int64_t utime,
                        const hal::AxisLayout& axes) {
  loomlcm::axes_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = s.tick;
  m.time_s = loop_time_s(s);
  m.crank_phase_rad = s.crank_phase_rad;
  m.beater_angle_rad = s.beater_angle_rad;
  m.beat_force_n = s.beat_force_valid ? s.beat_force_n : 0.0;
  m.beat_force_valid = s.beat_force_valid;
  const std::size_t n = std::min<std::size_t>(s.axis_count, hal::kMaxAxes);
  m.num_axes = static_cast<std::int8_t>(n);
  m.axes.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const AxisSample& a = s.axes[i];
    loomlcm::axis_t& o = m.axes[i];
    o.name = i < axes.count ? axes.name(i) : "axis" + std::to_string(i);
    o.unit = i < axes.count ? hal::axis_unit(axes.role(i)) : "";
    o.position = a.position;
    o.velocity = a.velocity;
    o.target = a.target;
    o.following_error = a.following_error;
    o.following_error_limit = a.following_error_limit;
    o.fault_code = a.fault_code;
    o.effort = a.effort;
    o.drive_state = hal::drive_state_name(static_cast<hal::DriveState>(a.drive_state));
    o.drive_state_code = static_cast<std::int8_t>(a.drive_state);
    o.request = static_cast<std::int8_t>(a.request);
  }
  return m;
}

loomlcm::rt_stats_t to_rt_stats(const Snapshot& s, const std::string& loom_id, std::int64_t utime,
                                std::uint64_t dropped, std::uint64_t backlog, std::uint64_t dropped_events) {
  loomlcm::rt_stats_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = s.tick;
  m.time_s = loop_time_s(s);
  m.period_ns = s.period_ns;
  m.overruns = s.overruns;
  m.tick_cost_ns = s.tick_cost_ns;
  m.max_tick_cost_ns = s.max_tick_cost_ns;
  m.wake_latency_p50_ns = s.wake_latency_p50_ns;
  m.wake_latency_p99_ns = s.wake_latency_p99_ns;
  m.wake_latency_max_ns = s.wake_latency_max_ns;
  m.dropped_snapshots = to_i64(dropped);
  m.dropped_events = to_i64(dropped_events);
  m.backlog = to_i64(backlog);
  m.can_tx_dropped = s.can_tx_dropped;
  m.can_rx_errors = s.can_rx_errors;
  return m;
}

const char* fault_kind_name(Event::FaultKind k) noexcept {
  switch (k) {
    case Event::FaultKind::kFirst:
      return "first";
    case Event::FaultKind::kDiagnosis:
      return "diagnosis";
    case Event::FaultKind::kDevice:
      return "device";
  }
  return "unknown";
}

namespace {
// The header every event message starts with: when it was sent, which loom, and the tick it happened at.
template <class Message>
Message event_message(const Event& e, const std::string& loom_id, std::int64_t utime) {
  Message m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = e.tick;
  m.time_s = seconds(e.tick, e.period_ns);
  return m;
}
}  // namespace

loomlcm::beat_t to_beat(const Event& e, const std::string& loom_id, std::int64_t utime) {
  auto m = event_message<loomlcm::beat_t>(e, loom_id, utime);
  m.row = static_cast<std::int32_t>(e.row);
  m.index = static_cast<std::int16_t>(e.beat_index);
  m.beats_per_row = static_cast<std::int16_t>(e.beats_per_row);
  m.x_m = e.x_m;
  m.peak_force_n = e.force_measured ? e.peak_force_n : 0.0;
  m.force_measured = e.force_measured;
  m.in_band = e.in_band;
  m.band_min_n = e.band_min_n;
  m.band_max_n = e.band_max_n;
  return m;
}

loomlcm::fault_t to_fault(const Event& e, const std::string& loom_id, std::int64_t utime,
                          const hal::AxisLayout& axes) {
  auto m = event_message<loomlcm::fault_t>(e, loom_id, utime);
  m.kind = fault_kind_name(e.fault_kind);
  const sequencer::Fault f = fault_of(e.fault);
  m.name = sequencer::fault_name(f);
  m.code = sequencer::fault_code(f);
  m.text = with_sensor(sequencer::fault_text(f), e.sensor);
  m.axis = axis_or_empty(axes, e.axis);
  m.device_code = e.device_code;
  m.state = state_of(e.state);
  m.row = static_cast<std::int32_t>(e.row);
  m.rows_done = e.rows_done;
  m.pick = e.pick;
  m.beat = e.beat;
  return m;
}

loomlcm::row_t to_row(const Event& e, const std::string& loom_id, std::int64_t utime) {
  auto m = event_message<loomlcm::row_t>(e, loom_id, utime);
  m.row = static_cast<std::int32_t>(e.row);
  m.row_s = seconds(e.row_ticks, e.period_ns);
  m.shed_s = seconds(e.shed_ticks, e.period_ns);
  m.pick_s = seconds(e.pick_ticks, e.period_ns);
  m.beat_s = seconds(e.beat_ticks, e.period_ns);
  m.beats = static_cast<std::int16_t>(e.beats);
  m.carriage_steps = static_cast<std::int16_t>(e.carriage_steps);
  m.force_measured = e.force_measured;
  m.force_min_n = e.force_measured ? e.force_min_n : 0.0;
  m.force_mean_n = e.force_measured ? e.force_mean_n : 0.0;
  m.force_max_n = e.force_measured ? e.force_max_n : 0.0;
  m.beats_in_band = static_cast<std::int16_t>(e.beats_in_band);
  m.band_min_n = e.band_min_n;
  m.band_max_n = e.band_max_n;
  m.knotting_s = seconds(e.knotting_ticks, e.period_ns);
  m.knot_s = seconds(e.knot_ticks, e.period_ns);
  m.weaver_s = seconds(e.weaver_ticks, e.period_ns);
  m.knots_tied = e.knots_tied;
  m.knots_retried = e.knots_retried;
  m.knots_by_hand = e.knots_by_hand;
  return m;
}

namespace {
sequencer::WeaverAsk ask_of(std::uint8_t v) noexcept {
  return v <= static_cast<std::uint8_t>(sequencer::WeaverAsk::kCheckKnot)
             ? static_cast<sequencer::WeaverAsk>(v)
             : sequencer::WeaverAsk::kNone;
}
std::string slot_colour_or_empty(const sequencer::KnotProgram* p, int slot) {
  return p != nullptr && slot >= 0 && slot < p->slots() ? p->slot_colour(slot) : std::string();
}
}  // namespace

loomlcm::knots_t to_knots(const Snapshot& s, const sequencer::KnotProgram& p, const std::string& loom_id,
                          std::int64_t utime) {
  const KnotSample& k = s.knots;
  loomlcm::knots_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = s.tick;
  m.time_s = loop_time_s(s);
  m.state = state_of(s.state);
  m.knotting = k.knotting;
  m.row = static_cast<std::int32_t>(s.row + 1);  // the row knotted is the one after the completed rows
  m.design_row = p.design_row(s.row);
  // The sample's counts bound every array (the program is the same machine's, but a ring slot is read
  // only as far as it was written).
  const int heads = std::min<int>({p.heads(), k.heads, static_cast<int>(hal::kMaxKnottingHeads)});
  const int slots = std::min<int>({p.slots(), k.slots, static_cast<int>(kMaxKnotSlots)});
  m.heads = static_cast<std::int16_t>(std::max(heads, 0));
  m.stripe = static_cast<std::int16_t>(p.stripe());
  m.knots_per_row = static_cast<std::int16_t>(p.knots_per_row());
  m.slots = static_cast<std::int16_t>(std::max(slots, 0));
  m.knots_per_slot = p.knots_per_slot();
  m.cycle = k.cycle;
  m.cycles_started = static_cast<std::int16_t>(k.cycles_started);
  m.cycles_done = static_cast<std::int16_t>(k.cycles_done);
  m.tied = k.tied;
  m.retried = k.retried;
  m.by_hand = k.by_hand;
  m.row_tied = k.row_tied;
  m.row_retried = k.row_retried;
  m.row_by_hand = k.row_by_hand;
  m.head_knot.resize(static_cast<std::size_t>(m.heads));
  m.head_slot.resize(static_cast<std::size_t>(m.heads));
  m.head_colour.resize(static_cast<std::size_t>(m.heads));
  m.stock.assign(static_cast<std::size_t>(m.heads),
                 std::vector<std::int32_t>(static_cast<std::size_t>(m.slots)));
  for (int h = 0; h < m.heads; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    const int knot = k.cycle >= 0 ? p.knot_of(h, k.cycle) : -1;
    const int slot = knot >= 0 ? p.slot(s.row, knot) : -1;
    m.head_knot[hh] = static_cast<std::int16_t>(knot);
    m.head_slot[hh] = static_cast<std::int16_t>(slot);
    m.head_colour[hh] = slot_colour_or_empty(&p, slot);
    for (int sl = 0; sl < m.slots; ++sl)
      m.stock[hh][static_cast<std::size_t>(sl)] = k.stock[hh][static_cast<std::size_t>(sl)];
  }
  m.slot_colour.resize(static_cast<std::size_t>(m.slots));
  for (int sl = 0; sl < m.slots; ++sl) m.slot_colour[static_cast<std::size_t>(sl)] = p.slot_colour(sl);
  m.knot_slot.resize(static_cast<std::size_t>(std::max(p.knots_per_row(), 0)));
  for (std::size_t i = 0; i < m.knot_slot.size(); ++i) {
    m.knot_slot[i] = static_cast<std::int16_t>(p.slot(s.row, static_cast<int>(i)));
  }
  m.requests = static_cast<std::int32_t>(k.requests);
  const sequencer::WeaverAsk ask = ask_of(k.ask);
  m.ask = ask == sequencer::WeaverAsk::kNone ? std::string() : sequencer::weaver_ask_name(ask);
  m.ask_knot = k.ask_knot;
  m.ask_head = k.ask_head;
  m.ask_slot = k.ask_slot;
  if (ask != sequencer::WeaverAsk::kNone) {
    sequencer::WeaverRequest q;
    q.ask = ask;
    q.row = k.ask_row;
    q.design_row = p.design_row(k.ask_row > 0 ? k.ask_row - 1 : 0);
    q.knot = k.ask_knot;
    q.head = k.ask_head;
    q.slot = k.ask_slot;
    m.ask_text = sequencer::describe(q, p);
  }
  return m;
}

loomlcm::weaver_request_t to_weaver_request(const Event& e, const sequencer::KnotProgram* p,
                                            const std::string& loom_id, std::int64_t utime) {
  auto m = event_message<loomlcm::weaver_request_t>(e, loom_id, utime);
  const sequencer::WeaverAsk ask = ask_of(e.ask);
  m.number = static_cast<std::int32_t>(e.request);
  m.ask = sequencer::weaver_ask_name(ask);
  m.row = static_cast<std::int32_t>(e.row);
  m.design_row = e.design_row;
  m.knot = e.knot;
  m.head = e.head;
  m.slot = e.slot;
  m.colour = slot_colour_or_empty(p, e.slot);
  sequencer::WeaverRequest q;
  q.ask = ask;
  q.row = e.row;
  q.design_row = e.design_row;
  q.knot = e.knot;
  q.head = e.head;
  q.slot = e.slot;
  if (p != nullptr) {
    m.text = sequencer::describe(q, *p);
  } else {
    m.text = "row " + std::to_string(e.row) + ": " + m.ask + " knot " + std::to_string(e.knot + 1) +
             " head " + std::to_string(e.head + 1) + " slot " + std::to_string(e.slot);
  }
  return m;
}

loomlcm::design_t to_design(const design::Design& d, std::uint64_t rows_done, const std::string& loom_id,
                            std::int64_t utime) {
  loomlcm::design_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.name = d.name();
  m.width = d.width();
  m.height = d.height();
  m.rows_done = static_cast<std::int64_t>(std::min<std::uint64_t>(rows_done, INT64_MAX));
  const design::DesignPosition next = design::position_after(d, rows_done);
  m.next_row = next.row + 1;
  m.repeat = next.repeat;
  m.n_colours = static_cast<std::int16_t>(d.palette().size());
  for (const design::Colour& c : d.palette()) {
    m.code.push_back(c.code);
    m.colour_name.push_back(c.name);
    m.rgb.push_back(static_cast<std::int32_t>(c.rgb));
  }
  // Absolute rows (counting every repeat) from the one knotted last to two after the next.
  const std::uint64_t first = rows_done > 0 ? rows_done - 1 : rows_done;
  const std::uint64_t h = static_cast<std::uint64_t>(d.height());
  for (std::uint64_t a = first; a <= rows_done + 2; ++a) {
    if (a == rows_done) m.next_index = static_cast<std::int16_t>(m.row_number.size());
    const int r = static_cast<int>(a % h);
    m.row_number.push_back(r + 1);
    const auto knots = d.row(r);
    m.knots.emplace_back(knots.begin(), knots.end());
  }
  m.n_rows = static_cast<std::int16_t>(m.row_number.size());
  return m;
}

}  // namespace loom::telemetry
