// The control cycle, its events and its telemetry snapshot.
#include "loom/firmware/control_loop.hpp"

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "loom/telemetry/telemetry.hpp"

namespace loom::firmware {
namespace {

static_assert(telemetry::kMaxKnotSlots == static_cast<std::size_t>(sequencer::kMaxMagazineSlots),
              "the snapshot holds every magazine slot");

// Bits 0..n-1 from n (<= 8) consecutive bools (little-endian words): with byte i at bit 8i, the multiply
// puts it at bit 56 + i (the 2^(7(8-i)) term) and every other term at a distinct lower bit or past bit 63,
// so nothing carries into the top byte.
static_assert(sizeof(bool) == 1);
std::uint8_t pack_flags(const unsigned char* first, std::size_t n) noexcept {
  std::uint64_t w = 0;
  std::memcpy(&w, first, n);
  return static_cast<std::uint8_t>((w * 0x0102040810204080ull) >> 56);
}
}  // namespace

ControlLoop::ControlLoop(hal::Hal& hal, sequencer::Sequencer& seq, telemetry::Telemetry* telemetry,
                         std::int64_t period_ns, bool lossless_telemetry)
    : hal_(hal),
      seq_(seq),
      n_axes_(seq.axes().count),
      telemetry_(telemetry),
      period_ns_(period_ns),
      lossless_(lossless_telemetry) {}

void ControlLoop::cycle(hal::Tick now) noexcept {
  hal_.read(now, in_);
  seq_.step(now, in_, out_);
  hal_.write(now, out_);
  if (telemetry_ != nullptr) {
    // Events first: the publisher sends a tick's events before that tick's samples.
    // The usual tick has no event and no device reporting a fault: one branch-free pass over the flags.
    if (!seq_.events().empty() || any_device_event()) push_events(now);
    fill_snapshot(now);
    if (lossless_) {
      telemetry_->push_waiting(snap_);
    } else {
      telemetry_->push(snap_);
    }
  }
}

std::uint32_t ControlLoop::row_in_progress() const noexcept {
  // Once the run is done the last row woven is "the row"; otherwise it is the one being (or about
  // to be) woven, so row 1 reads 1 while it is woven.
  const std::uint32_t done = seq_.counters().rows;
  return seq_.state() == sequencer::State::kDone && done > 0 ? done : done + 1;
}

void ControlLoop::push_event(const telemetry::Event& e) noexcept {
  if (lossless_) {
    telemetry_->push_event_waiting(e);
  } else {
    telemetry_->push_event(e);
  }
}

void ControlLoop::fill_event_context(telemetry::Event& e, hal::Tick now) const noexcept {
  e.tick = now;
  e.period_ns = period_ns_;
  e.row = row_in_progress();
  e.rows_done = seq_.counters().rows;
  e.pick = seq_.counters().picks;
  e.beat = seq_.counters().beats;
  e.beats_per_row = static_cast<std::uint16_t>(seq_.profiles().beats_per_row());
  e.band_min_n = ctx_.beat_force_min_n;
  e.band_max_n = ctx_.beat_force_max_n;
}

// True when a drive or the link raised a fault event in this tick's read (the HAL's events, not sequencer
// state): one branch-free pass over the flags.
bool ControlLoop::any_device_event() const noexcept {
  bool any = in_.link.fault_raised;
  for (std::size_t i = 0; i < n_axes_; ++i) any |= in_.axes[i].fault_raised;
  return any;
}

// The sequencer's events of this tick, forwarded in its order (BEAT, ROW, WEAVER, FAULT), then what the
// drives and the link report themselves (the HAL's fault events).

void ControlLoop::push_events(hal::Tick now) noexcept {
  const sequencer::TickEvents& events = seq_.events();
  int first_axis_reported = -2;  // axis of a first/diagnosis event this tick (-1: none), -2: no such event
  bool link_reported = false;
  {
    // A fault latched and refined in the same tick is one FAULT (first) with what is known at its end.
    const bool latched = events.has(sequencer::EventKind::kFaultLatched);
    for (const sequencer::TickEvent& ev : events) {  // bounded: TickEvents::kCapacity
      switch (ev.kind) {
        case sequencer::EventKind::kBeat:
          push_beat(ev.beat, now);
          break;
        case sequencer::EventKind::kRow:
          push_row(now);
          break;
        case sequencer::EventKind::kWeaverRequest:
          push_weaver_request(now);
          break;
        case sequencer::EventKind::kFaultLatched:
        case sequencer::EventKind::kDiagnosisRefined:
          if (latched && ev.kind == sequencer::EventKind::kDiagnosisRefined) break;
          push_fault(latched ? telemetry::Event::FaultKind::kFirst : telemetry::Event::FaultKind::kDiagnosis,
                     seq_.first_fault(), seq_.fault_axis(), seq_.fault_detail(), seq_.fault_sensor(), now);
          first_axis_reported = seq_.fault_axis();
          link_reported = seq_.first_fault() == sequencer::Fault::kLinkFault ||
                          (seq_.first_fault() == sequencer::Fault::kHeartbeatLost && seq_.fault_axis() < 0);
          break;
        default:
          break;  // picks, pauses, knot progress and buttons travel in the snapshot and the reporter
      }
    }
  }
  push_device_faults(first_axis_reported, link_reported, now);
}

void ControlLoop::push_beat(const sequencer::BeatEvent& b, hal::Tick now) noexcept {
  telemetry::Event e;
  e.kind = telemetry::Event::Kind::kBeat;
  fill_event_context(e, now);
  e.row = b.row;
  e.beat_index = b.index;
  e.x_m = b.x_m;
  e.peak_force_n = b.peak_force_n;
  e.force_measured = b.force_measured;
  e.in_band = b.in_band;
  push_event(e);
}

// ROW: the completed row with its time split and force summary.
void ControlLoop::push_row(hal::Tick now) noexcept {
  const sequencer::RowStats& r = seq_.last_row();
  telemetry::Event e;
  e.kind = telemetry::Event::Kind::kRow;
  fill_event_context(e, now);
  e.row = r.row;
  e.row_ticks = r.total_ticks;
  e.shed_ticks = r.shed_ticks;
  e.pick_ticks = r.pick_ticks;
  e.beat_ticks = r.beat_ticks;
  e.knotting_ticks = r.knotting_ticks;
  e.beats = static_cast<std::uint16_t>(r.beats);
  e.carriage_steps = static_cast<std::uint16_t>(r.carriage_steps);
  e.force_measured = r.force_measured;
  e.force_min_n = r.force_min_n;
  e.force_mean_n = r.force_mean_n;
  e.force_max_n = r.force_max_n;
  e.knot_ticks = r.knot_ticks;
  e.weaver_ticks = r.weaver_ticks;
  e.knots_tied = static_cast<std::uint16_t>(r.knots_tied);
  e.knots_retried = static_cast<std::uint16_t>(r.knots_retried);
  e.knots_by_hand = static_cast<std::uint16_t>(r.knots_by_hand);
  std::uint16_t in_band = 0;
  const int n = r.beats < sequencer::kMaxBeatsPerRow ? r.beats : sequencer::kMaxBeatsPerRow;
  for (int k = 0; r.force_measured && k < n; ++k) {  // bounded: kMaxBeatsPerRow
    const double f = r.beat[static_cast<std::size_t>(k)].peak_force_n;
    if (f >= ctx_.beat_force_min_n && f <= ctx_.beat_force_max_n) ++in_band;
  }
  e.beats_in_band = in_band;
  push_event(e);
}

// WEAVER: a request the knotting heads made of the weaver; the publisher words it.
void ControlLoop::push_weaver_request(hal::Tick now) noexcept {
  const sequencer::WeaverRequest& q = seq_.knotter().request();
  telemetry::Event e;
  e.kind = telemetry::Event::Kind::kWeaver;
  fill_event_context(e, now);
  e.row = q.row;
  e.ask = static_cast<std::uint8_t>(q.ask);
  e.request = seq_.weaver_requests();
  e.design_row = q.design_row;
  e.knot = static_cast<std::int16_t>(q.knot);
  e.head = static_cast<std::int16_t>(q.head);
  e.slot = static_cast<std::int16_t>(q.slot);
  push_event(e);
}

void ControlLoop::push_fault(telemetry::Event::FaultKind kind, sequencer::Fault which, int axis,
                             std::uint16_t device_code, int sensor, hal::Tick now) noexcept {
  telemetry::Event e;
  e.kind = telemetry::Event::Kind::kFault;
  fill_event_context(e, now);
  e.fault_kind = kind;
  e.fault = static_cast<std::uint8_t>(which);
  e.axis = static_cast<std::int8_t>(axis);
  e.device_code = device_code;
  e.sensor = static_cast<std::int8_t>(sensor);
  e.state = static_cast<std::uint8_t>(seq_.events().began_in());
  push_event(e);
}

// Every drive's and the link's own fault report, once: the HAL raises an event on the tick a report
// begins (or, for a drive, changes its code; hal/fault_events.hpp). Pushed unless the sequencer's first
// fault or diagnosis already names that axis or the link this tick.
void ControlLoop::push_device_faults(int first_axis_reported, bool link_reported, hal::Tick now) noexcept {
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const hal::AxisFeedback& a = in_.axes[i];
    if (a.fault_raised && static_cast<int>(i) != first_axis_reported) {
      push_fault(telemetry::Event::FaultKind::kDevice, sequencer::Fault::kDriveFault, static_cast<int>(i),
                 a.fault_code, -1, now);
    }
  }
  if (in_.link.fault_raised && !link_reported) {
    push_fault(telemetry::Event::FaultKind::kDevice, sequencer::Fault::kLinkFault, -1,
               in_.link.link_fault_code, -1, now);
  }
}

void ControlLoop::fill_snapshot(hal::Tick now) noexcept {
  telemetry::Snapshot& s = snap_;
  s.tick = now;
  s.period_ns = period_ns_;
  // Enums, named by the publisher; the fault's code is looked up only when the fault changed.
  s.state = static_cast<std::uint8_t>(seq_.state());
  const sequencer::Fault f = seq_.first_fault();
  const bool faulted = f != sequencer::Fault::kNone;
  s.first_fault = static_cast<std::uint8_t>(f);
  if (!code_shown_ || f != shown_first_fault_) {
    shown_first_fault_ = f;
    s.first_fault_code = sequencer::fault_code(f);
    code_shown_ = true;
  }
  s.fault_axis = static_cast<std::int8_t>(faulted ? seq_.fault_axis() : -1);
  s.fault_sensor = static_cast<std::int8_t>(faulted ? seq_.fault_sensor() : -1);
  s.fault_device_code = faulted ? seq_.fault_detail() : 0;
  s.fault_tick = faulted ? seq_.fault_tick() : hal::kNeverTick;
  s.stopped_by = static_cast<std::uint8_t>(faulted ? seq_.stopped_by() : sequencer::Fault::kNone);
  s.row = seq_.counters().rows;
  s.pick = seq_.counters().picks;
  s.beat = seq_.counters().beats;
  s.row_in_progress = row_in_progress();
  s.rows_target = ctx_.rows_target;
  s.beats_per_row = static_cast<std::uint16_t>(seq_.profiles().beats_per_row());
  // commanded_rocker_angle() is the rocker table at commanded_crank_phase(): the phase is wrapped (an
  // fmod of the unwrapped crank, ~100 instructions) once here instead of twice, and both are kept
  // while the crank's target and the recipe stay the same (shed, pick, idle).
  const double crank_target = out_.axes[hal::index(hal::CoreAxis::kBeatCrank)].target_position;
  if (!crank_shown_ || crank_target != shown_crank_target_ || seq_.recipe_changes() != shown_recipe_) {
    s.crank_phase_rad = seq_.commanded_crank_phase();
    s.beater_angle_rad = seq_.profiles().rocker().at(s.crank_phase_rad).value;
    crank_shown_ = true;
    shown_crank_target_ = crank_target;
    shown_recipe_ = seq_.recipe_changes();
  }
  s.beat_force_valid = in_.analog.beat_force_valid;
  s.beat_force_n = in_.analog.beat_force_valid ? in_.analog.beat_force_n : 0.0;
  s.axis_count = static_cast<std::uint8_t>(n_axes_);
  for (std::size_t i = 0; i < n_axes_; ++i) {
    telemetry::AxisSample& a = s.axes[i];
    a.position = in_.axes[i].position;
    a.velocity = in_.axes[i].velocity;
    a.target = out_.axes[i].target_position;
    a.following_error = a.target - a.position;
    a.following_error_limit = ctx_.following_error_limit[i];
    a.effort = in_.axes[i].effort;
    a.fault_code = in_.axes[i].fault_code;
    a.drive_state = static_cast<std::uint8_t>(in_.axes[i].state);
    a.request = static_cast<std::uint8_t>(out_.axes[i].request);
  }
  s.outputs =
      static_cast<std::uint8_t>((out_.io.piston_a_extend ? 1 : 0) | (out_.io.piston_b_extend ? 2 : 0));
  const auto& io = in_.io;
  static_assert(hal::kSafetySensorCount == 6, "inputs_2 packs six second channels");
  if constexpr (std::endian::native == std::endian::little) {
    // The seven flags (A ext … estop_ok, declared in bit order) and the six second channels are runs of
    // bools, bytes of 0 or 1: one multiply gathers byte i of a word into bit i of its top byte.
    using hal::DigitalInputs;
    static_assert(
        offsetof(DigitalInputs, piston_a_retracted) == offsetof(DigitalInputs, piston_a_extended) + 1 &&
            offsetof(DigitalInputs, piston_b_extended) == offsetof(DigitalInputs, piston_a_extended) + 2 &&
            offsetof(DigitalInputs, piston_b_retracted) == offsetof(DigitalInputs, piston_a_extended) + 3 &&
            offsetof(DigitalInputs, shuttle_at_left) == offsetof(DigitalInputs, piston_a_extended) + 4 &&
            offsetof(DigitalInputs, shuttle_at_right) == offsetof(DigitalInputs, piston_a_extended) + 5 &&
            offsetof(DigitalInputs, estop_ok) == offsetof(DigitalInputs, piston_a_extended) + 6,
        "the seven input flags are consecutive bytes in bit order");
    const auto* bytes = reinterpret_cast<const unsigned char*>(&io);
    s.inputs = pack_flags(bytes + offsetof(DigitalInputs, piston_a_extended), 7);
    s.inputs_2 = pack_flags(bytes + offsetof(DigitalInputs, second_channel), hal::kSafetySensorCount);
  } else {
    s.inputs = static_cast<std::uint8_t>((io.piston_a_extended ? 1 : 0) | (io.piston_a_retracted ? 2 : 0) |
                                         (io.piston_b_extended ? 4 : 0) | (io.piston_b_retracted ? 8 : 0) |
                                         (io.shuttle_at_left ? 16 : 0) | (io.shuttle_at_right ? 32 : 0) |
                                         (io.estop_ok ? 64 : 0));
    const auto& c2 = io.second_channel;
    s.inputs_2 = static_cast<std::uint8_t>((c2[0] ? 1 : 0) | (c2[1] ? 2 : 0) | (c2[2] ? 4 : 0) |
                                           (c2[3] ? 8 : 0) | (c2[4] ? 16 : 0) | (c2[5] ? 32 : 0));
  }
  s.overruns = stats_.overruns;
  s.tick_cost_ns = stats_.last_tick_cost_ns;
  s.max_tick_cost_ns = stats_.max_tick_cost_ns;
  s.wake_latency_p50_ns = stats_.wake_latency_p50_ns;
  s.wake_latency_p99_ns = stats_.wake_latency_p99_ns;
  s.wake_latency_max_ns = stats_.wake_latency_max_ns;
  s.telemetry_dropped = static_cast<std::uint32_t>(telemetry_->dropped());
  s.can_tx_dropped = in_.link.tx_dropped;
  s.can_rx_errors = in_.link.rx_errors;
  if (ctx_.knot_program != nullptr) fill_knots();
}

// The heads' progress changes only while they tie: outside the knotting state (and after the tick that
// left it) the previous values stand and nothing is copied.
void ControlLoop::fill_knots() noexcept {
  telemetry::KnotSample& k = snap_.knots;
  const bool knotting = seq_.state() == sequencer::State::kKnotting;
  if (knots_shown_ && !knotting && !k.knotting) return;
  const sequencer::KnotProgram& p = *ctx_.knot_program;
  const sequencer::RowKnotter& r = seq_.knotter();
  const int heads = p.heads() < static_cast<int>(hal::kMaxKnottingHeads)
                        ? p.heads()
                        : static_cast<int>(hal::kMaxKnottingHeads);
  const int slots = p.slots() < sequencer::kMaxMagazineSlots ? p.slots() : sequencer::kMaxMagazineSlots;
  k.heads = static_cast<std::uint8_t>(heads > 0 ? heads : 0);
  k.slots = static_cast<std::uint8_t>(slots > 0 ? slots : 0);
  k.knotting = knotting;
  k.cycle = static_cast<std::int16_t>(knotting ? r.cycle() : -1);
  const sequencer::KnotCounters& c = seq_.counters().knot;
  k.cycles_started = static_cast<std::uint16_t>(c.cycles_started);
  k.cycles_done = static_cast<std::uint16_t>(c.cycles_done);
  k.tied = c.tied;
  k.retried = c.retried;
  k.by_hand = c.by_hand;
  k.row_tied = static_cast<std::uint16_t>(r.row().tied);
  k.row_retried = static_cast<std::uint16_t>(r.row().retried);
  k.row_by_hand = static_cast<std::uint16_t>(r.row().by_hand);
  k.requests = seq_.weaver_requests();
  const sequencer::WeaverRequest& q = seq_.weaver_request();  // kNone unless knotting
  k.ask = static_cast<std::uint8_t>(q.ask);
  k.ask_knot = static_cast<std::int16_t>(q.knot);
  k.ask_head = static_cast<std::int16_t>(q.head);
  k.ask_slot = static_cast<std::int16_t>(q.slot);
  k.ask_row = q.row;
  for (int h = 0; h < heads; ++h) {  // bounded: 12 heads × 16 slots
    for (int sl = 0; sl < slots; ++sl) {
      k.stock[static_cast<std::size_t>(h)][static_cast<std::size_t>(sl)] = r.stock(h, sl);
    }
  }
  knots_shown_ = true;
}

}  // namespace loom::firmware
