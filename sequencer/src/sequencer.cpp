// The row cycle. One tick runs these steps in this order (LinuxCNC's emcmotController pattern); each
// is one function below, in the same order:
//   1. sense()             debounce sensors and buttons (the e-stop chain is never filtered)
//   2. check_faults()      e-stop, stop-now, drives (fault, EMCY), link, non-finite or jumping feedback,
//                          the load cell, impossible sensor pictures, staleness → latch the first fault
//   3. refine_diagnosis()  in a fault: a root cause seen within the diagnosis window replaces a symptom
//   4. report_presses()    buttons and pedal → kButton events only (the owner makes them requests)
//   5. run_state()         the current state's own function; the states, in cycle order:
//        idle → enabling → positioning → shed_test → shed → pick → (shed → pick …) → beat_sweep
//        → row_end (only when the row's counters must be on disk first) → await_knotting (the weaver
//        knots) or knotting (the heads tie the row: RowKnotter) → shed …;   paused, done, fault
//   6. play_moves()        sample the active moves and profiles into targets; count beats
//   7. track_beat_force()  the load cell's peak per beat
//   8. interlocks          judge the proposed outputs against the measured inputs; a trip latches
//   9. signal()            the stack light
// What is news (a beat, a pick, a row, a fault, a pause …) is appended to events_ where it happens.
// A fault found in step 2 wins over any plan: the state functions then only hold.
#include "loom/sequencer/sequencer.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "loom/motion/angles.hpp"

namespace loom::sequencer {
namespace {
using hal::AxisRequest;
using hal::CoreAxis;
using hal::DriveState;
using hal::index;
constexpr double kArrivalMarginM = 0.002;  // carrier position uncertainty at the arrival sensor
constexpr double kCarrierAtSelvedgeM =
    1e-6;  // a pick starting farther off its selvedge (a cut pick) is re-planned
constexpr double kStepPlausibility = 4.0;  // an axis may move at most this × its top speed per tick
constexpr int kShedTestStrokes = 4;        // arming shed test: A up, B up, A up, B up

void request_all(hal::HalOutputs& o, std::size_t n_axes, AxisRequest r) {
  for (std::size_t i = 0; i < n_axes; ++i) o.axes[i].request = r;
}
bool finite(double x) {
  return std::isfinite(x);
}
}  // namespace

namespace {
bool drive_in_fault(const hal::AxisFeedback& a) {
  return a.fault || a.state == DriveState::kFault || a.state == DriveState::kFaultReactionActive;
}
}  // namespace

const char* state_name(State s) {
  switch (s) {
    case State::kIdle:
      return "idle";
    case State::kEnabling:
      return "enabling";
    case State::kHoming:
      return "homing";
    case State::kPositioning:
      return "positioning";
    case State::kShedTest:
      return "shed_test";
    case State::kShed:
      return "shed";
    case State::kPick:
      return "pick";
    case State::kBeatSweep:
      return "beat_sweep";
    case State::kRowEnd:
      return "row_end";
    case State::kAwaitKnotting:
      return "await_knotting";
    case State::kKnotting:
      return "knotting";
    case State::kPaused:
      return "paused";
    case State::kDone:
      return "done";
    case State::kFault:
      return "fault";
  }
  return "?";
}

std::optional<SequencerFault> find_fault(const SequencerConfig& c, const motion::ProfileSet& p) {
  using F = SequencerField;
  const auto fault = [](F field, std::string message, std::size_t axis = 0) {
    return SequencerFault{field, axis, std::move(message)};
  };
  const auto fin = [](double v) { return std::isfinite(v); };
  if (!(c.period_s > 0.0) || !fin(c.period_s))
    return fault(F::kPeriod, "timing.period_ms must be positive and finite");
  if (p.beats_per_row() > kMaxBeatsPerRow) {
    return fault(F::kBeatsPerPosition,
                 "recipe.beats_per_position = " + std::to_string(p.spec().beats_per_position) + " gives " +
                     std::to_string(p.beats_per_row()) + " beats per row; the sequencer holds at most " +
                     std::to_string(kMaxBeatsPerRow) +
                     " (narrow the loom or beat each position fewer times)");
  }
  if (c.picks_per_row < 1) return fault(F::kPicksPerRow, "recipe.picks_per_row must be at least 1");
  const BeatRegulatorConfig& br = c.beat_regulator;
  if (!(br.min_speed_scale > 0.0 && br.min_speed_scale <= 1.0) ||
      !(br.max_speed_scale >= 1.0 && br.max_speed_scale <= 2.0)) {
    return fault(F::kBeatRegulator,
                 "beat regulator: speed scale bounds must satisfy 0 < min <= 1 <= max <= 2");
  }
  if (!(br.memory_weight > 0.0 && br.memory_weight <= 1.0) ||
      !(br.drift_weight > 0.0 && br.drift_weight <= 1.0)) {
    return fault(F::kBeatRegulator, "beat regulator: memory and drift weights must be in (0, 1]");
  }
  if (c.axes.count < hal::kCoreAxisCount || c.axes.count > hal::kMaxAxes) {
    return fault(F::kAxes, "axes: the loom has " + std::to_string(c.axes.count) +
                               " axes; it needs the three core axes and holds at most " +
                               std::to_string(hal::kMaxAxes));
  }
  for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
    if (c.axes.role(i) != static_cast<hal::AxisRole>(i)) {
      return fault(F::kAxes, std::string("axes: slot ") + std::to_string(i) + " must hold the " +
                                 hal::axis_role_name(static_cast<hal::AxisRole>(i)) + " axis");
    }
  }
  for (std::size_t i = hal::kCoreAxisCount; i < c.axes.count; ++i) {
    if (!std::isfinite(c.axis_max_speed[i]) || !(c.axis_max_speed[i] > 0.0)) {
      return fault(F::kAxisMaxSpeed,
                   std::string("axes.") + c.axes.name(i) + ".max_speed must be positive and finite", i);
    }
  }
  if (c.debounce_ticks < 1) return fault(F::kDebounceTicks, "timing.debounce_ticks must be at least 1");
  if (!fin(c.sensor_discrepancy_s) || c.sensor_discrepancy_s < c.period_s || c.sensor_discrepancy_s > 1.0) {
    return fault(F::kSensorDiscrepancy,
                 "timing.sensor_discrepancy_ms must be between one period and 1000 ms");
  }
  const struct {
    F field;
    const char* key;
    double v;
  } offsets[] = {{F::kCrankParkPosition, "beatup.crank_park_position_rad", c.crank_park_position_rad},
                 {F::kCarriageHome, "carriage.home_position_m", c.carriage_home_m},
                 {F::kHelixLeftPosition, "helix.left_position_rad", c.helix_left_position_rad}};
  for (const auto& o : offsets) {
    if (!fin(o.v) || std::abs(o.v) > 1e6)
      return fault(o.field, std::string(o.key) + " must be finite and within ±1e6");
  }
  // Every time-out becomes a tick count: it must be finite and fit the integer time base with room.
  const struct {
    F field;
    const char* key;
    double s;
  } times[] = {{F::kEnableTimeout, "timing.enable_timeout_s", c.enable_timeout_s},
               {F::kPickTimeoutMargin, "timing.pick_timeout_margin_s", c.pick_timeout_margin_s},
               {F::kStaleTimeout, "timing.stale_timeout_ms", c.stale_timeout_s},
               {F::kDiagnosisWindow, "diagnosis window", c.diagnosis_window_s},
               {F::kArrivalGrace, "arrival grace", c.arrival_grace_s},
               {F::kRowSaveTimeout, "timing.row_save_timeout_s", c.row_save_timeout_s}};
  for (const auto& t : times) {
    if (!fin(t.s) || t.s < 0.0 || t.s / c.period_s > 1e12) {
      return fault(t.field, std::string(t.key) + " must be a finite time below 1e12 periods");
    }
  }
  if (!(c.selvedge_sensor_window_m > 0.0) || !fin(c.selvedge_sensor_window_m)) {
    return fault(F::kSelvedgeSensorWindow, "machine selvedge sensor window must be positive and finite");
  }
  if (!(c.shuttle_follow_tolerance_m > 0.0) || !(c.shuttle_follow_tolerance_m < c.selvedge_sensor_window_m)) {
    return fault(F::kShuttleFollowTolerance,
                 "shuttle follow tolerance must be positive and below the selvedge sensor window");
  }
  if ((c.heads.program == nullptr) != (c.heads.cycle == nullptr)) {
    return fault(F::kKnottingHeads, "knotting heads: a knot program needs its knot cycle");
  }
  if (c.heads.program != nullptr) {
    if (c.knotting) {
      return fault(F::kKnottingMode,
                   "knotting.mode: the weaver's knotting and the knotting heads exclude each other");
    }
    const int heads = c.heads.program->heads();
    if (c.heads.program->slots() < 1 || c.heads.program->slots() > kMaxMagazineSlots) {
      return fault(F::kSlotColours, "knotting.slot_colours: 1..16 slots");
    }
    for (int h = 0; h < heads; ++h) {
      const auto hh = static_cast<std::size_t>(h);
      const int kn = c.heads.knotter_axis[hh], sel = c.heads.selector_axis[hh];
      const auto slot_ok = [&](int a, hal::AxisRole role) {
        return a >= static_cast<int>(hal::kCoreAxisCount) && a < static_cast<int>(c.axes.count) &&
               c.axes.role(static_cast<std::size_t>(a)) == role;
      };
      if (!slot_ok(kn, hal::AxisRole::kKnotter) || !slot_ok(sel, hal::AxisRole::kSelector)) {
        return fault(F::kKnottingHeads, "knotting heads: head " + std::to_string(h + 1) +
                                            " needs a knotter and a selector axis");
      }
    }
    const auto fin_pos = [&](double v) { return std::isfinite(v) && v > 0.0; };
    if (!fin_pos(c.heads.selector.velocity) || !fin_pos(c.heads.selector.acceleration) ||
        !fin_pos(c.heads.selector.jerk)) {
      return fault(F::kSelectorLimits, "knotting.selector limits must be positive and finite");
    }
    if (!fin_pos(c.heads.servo_tolerance_rad) || !std::isfinite(c.heads.settle_s) || c.heads.settle_s < 0.0 ||
        !std::isfinite(c.heads.take_position_rad) || !std::isfinite(c.heads.selector_zero_rad)) {
      return fault(F::kKnotterSettings,
                   "knotting: servo tolerance, settle time and commissioning offsets must be finite");
    }
    if (const double t = c.heads.placement_tolerance_m, pitch = c.heads.program->pitch_m();
        !std::isfinite(t) || t < 0.0 || t >= 0.5 * pitch) {
      return fault(F::kKnotterSettings,
                   "knotting.placement_tolerance_m must be below half the knot pitch (0: the default)");
    }
  }
  return std::nullopt;
}

std::string validate(const SequencerConfig& c, const motion::ProfileSet& p) {
  const std::optional<SequencerFault> f = find_fault(c, p);
  return f ? f->message : std::string();
}

Sequencer::Sequencer(motion::ProfileSlot& slot, const SequencerConfig& cfg, Counters resume)
    : Sequencer(slot.active(), cfg, resume) {
  slot_ = &slot;
}

Sequencer::Sequencer(const motion::ProfileSet& profiles, const SequencerConfig& cfg, Counters resume)
    : profiles_(&profiles),
      cfg_(cfg),
      counters_(resume),
      sensors_(cfg.debounce_ticks),
      second_channels_(cfg.debounce_ticks),
      buttons_(cfg.debounce_ticks),
      n_axes_(cfg.axes.count) {
  if (const std::string why = validate(cfg_, *profiles_); !why.empty()) throw std::invalid_argument(why);
  // Each channel is debounced first, so two healthy channels can be that many ticks apart: the
  // discrepancy time is never shorter than the debounce plus one tick, whatever the period.
  dual_ = DualChannelSensors(cfg_.second_channel, std::max(static_cast<int>(ticks(cfg_.sensor_discrepancy_s)),
                                                           cfg_.debounce_ticks + 1));
  stale_ticks_ = ticks(cfg_.stale_timeout_s);
  diagnosis_ticks_ = ticks(cfg_.diagnosis_window_s);
  arrival_grace_ticks_ = ticks(cfg_.arrival_grace_s);
  enable_timeout_ticks_ = ticks(cfg_.enable_timeout_s);
  row_save_timeout_ticks_ = ticks(cfg_.row_save_timeout_s);
  interlock_ctx_.warp = &profiles_->beatup().warp();
  interlock_ctx_.crank_park_position = cfg_.crank_park_position_rad;
  if (cfg_.heads.program != nullptr && cfg_.heads.cycle != nullptr) configure_knot_guard();
  knotter_.configure(cfg_.heads, &interlock_ctx_.knot, cfg_.period_s, cfg_.carriage_home_m, cfg_.carriage,
                     cfg_.stale_timeout_s);
  adopt_limits();
}

void Sequencer::configure_knot_guard() {
  interlock_ctx_.knot = sequencer::knot_guard(cfg_.heads);
}

void Sequencer::adopt_limits() noexcept {
  const motion::ProfileSpec& s = profiles_->spec();
  const double dt = cfg_.period_s;
  // The beat regulator's bounds for this recipe (a new recipe's positions start unremembered), aiming at
  // the band's middle, where either edge is farthest.
  const BeatRegulatorLimits limits = sweep_clock_.configure(
      *profiles_, dt, cfg_.beat_regulator, 0.5 * (cfg_.beat_force_min_n + cfg_.beat_force_max_n));
  regulator_.configure(cfg_.beat_regulator, limits,
                       profiles_->beats_per_row() / std::max(1, s.beats_per_position));
  // The crank's fastest is the regulator's fastest beat.
  const double crank_top = s.crank.velocity * (cfg_.beat_regulator.enabled ? limits.max_scale : 1.0);
  max_step_[index(CoreAxis::kBeatCrank)] = kStepPlausibility * crank_top * dt + 1e-3;
  max_step_[index(CoreAxis::kCarriage)] =
      kStepPlausibility * std::max(s.carriage_max_speed_m_s, cfg_.carriage.velocity) * dt + 1e-4;
  max_step_[index(CoreAxis::kHelix)] = kStepPlausibility * profiles_->helix_limits().velocity * dt + 1e-3;
  for (std::size_t i = hal::kCoreAxisCount; i < n_axes_; ++i) {
    max_step_[i] = kStepPlausibility * cfg_.axis_max_speed[i] * dt + 1e-3;
  }
}

hal::Tick Sequencer::ticks(double seconds) const noexcept {
  return static_cast<hal::Tick>(std::ceil(seconds / cfg_.period_s));
}

double Sequencer::seconds_since(hal::Tick now, hal::Tick t0) const noexcept {
  return static_cast<double>(now - t0) * cfg_.period_s;
}

double Sequencer::commanded_crank_phase() const noexcept {
  return motion::wrap_two_pi(cmd_.axes[index(CoreAxis::kBeatCrank)].target_position -
                             cfg_.crank_park_position_rad);
}

double Sequencer::commanded_rocker_angle() const noexcept {
  return profiles_->rocker().at(commanded_crank_phase()).value;
}

void Sequencer::latch(Fault f, hal::Tick now, int axis, std::uint16_t detail, int sensor) noexcept {
  if (first_fault_ == Fault::kNone) {
    first_fault_ = stopped_by_ = f;
    fault_axis_ = axis;
    fault_sensor_ = sensor;
    fault_detail_ = detail;
    fault_tick_ = now;
    add_fault_event(EventKind::kFaultLatched);
  }
  // An acknowledgement counts only as a deliberate act after the fault: one given before (a press while
  // weaving, a command racing the fault) is discarded here, whatever its source.
  ack_requested_ = false;
  crank_move_.active = carriage_move_.active = helix_move_.active = false;
  sweeping_ = false;
  sweep_clock_.stop();
  enter(State::kFault, now);
}

void Sequencer::enter(State s, hal::Tick now) noexcept {
  // Resumed only when the loom goes on from a pause: a stop (done) or a fault ends the pause, not resumes it.
  if (s == State::kPaused && state_ != State::kPaused) events_.add(EventKind::kPaused);
  if (state_ == State::kPaused && s != State::kPaused && s != State::kDone && s != State::kFault) {
    events_.add(EventKind::kResumed);
  }
  state_ = s;
  state_since_ = now;
}

void Sequencer::request_stop() noexcept {
  switch (state_) {
    case State::kIdle:
      start_requested_ =
          false;  // nothing moves yet: a start not taken is cancelled, no stop is kept for later
      return;
    case State::kDone:
    case State::kFault:
      return;
    default:
      stop_requested_ = true;
      return;
  }
}

bool Sequencer::hold_here(hal::Tick now) noexcept {
  // The points where the loom may stand (beater parked or between beats of no row, shuttle at a selvedge,
  // no knot cycle under way): a stop ends the run here, a pause holds here.
  if (stop_requested_) {
    enter(State::kDone, now);
    return true;
  }
  if (pause_requested_) {
    enter(State::kPaused, now);
    return true;
  }
  return false;
}

void Sequencer::add_fault_event(EventKind kind) noexcept {
  TickEvent& e = events_.add(kind);
  e.fault = first_fault_;
  e.axis = static_cast<std::int8_t>(fault_axis_);
  e.sensor = static_cast<std::int8_t>(fault_sensor_);
  e.detail = fault_detail_;
}

// ---------------------------------------------------------------------------------------------------
// The tick
// ---------------------------------------------------------------------------------------------------

void Sequencer::step(hal::Tick now, const hal::HalInputs& raw, hal::HalOutputs& out) noexcept {
  events_.clear(state_);
  sense(raw);
  // The sequencer and its interlocks see debounced sensors: a copy of the inputs with them, of the
  // configured axes only (the arrays are sized for the capacity).
  cur_ ^= 1;  // the last tick's inputs become last(i)
  hal::HalInputs& in = in_[cur_];
  for (std::size_t i = 0; i < n_axes_; ++i) in.axes[i] = raw.axes[i];  // (std::copy_n: a memcpy call)
  in.io = io_;
  in.analog = raw.analog;
  in.link = raw.link;
  if (state_ != State::kIdle && state_ != State::kFault) check_faults(now, in);
  if (external_fault_ != Fault::kNone) {  // the runner's overrun policy: latched once, like any fault
    if (state_ != State::kFault) latch(external_fault_, now);
    external_fault_ = Fault::kNone;
  }
  if (state_ == State::kFault) refine_diagnosis(now, in);
  report_presses();
  if (state_ == State::kIdle && start_requested_ && !in.io.estop_ok) {
    start_requested_ = false;
    latch(Fault::kEStop, now);
  }
  acknowledged_this_tick_ = false;
  run_state(now, in);
  if (state_ == State::kFault) {
    // Quick stop, hold the last targets, valves keep their state (a stopped shuttle is never clamped),
    // grippers keep their yarn, no cutter fires.
    request_all(cmd_, n_axes_, AxisRequest::kQuickStop);
    cmd_.io.cutter.fill(false);
  } else {
    if (acknowledged_this_tick_) request_all(cmd_, n_axes_, AxisRequest::kFaultReset);
    play_moves(now);
    track_beat_force(in);
    if (enabled_outputs_) {
      const Fault f = check_interlocks(interlock_ctx_, in, prev_cmd_, cmd_);
      if (f != Fault::kNone) {
        cmd_ = prev_cmd_;
        latch(f, now);
        request_all(cmd_, n_axes_, AxisRequest::kQuickStop);
      }
    }
  }
  signal();
  positions_primed_ = state_ != State::kIdle;
  // The configured axes and the I/O to the HAL (the arrays are sized for the capacity; the rest is never
  // used), in one pass: two library memcpy calls cost more than the copying. The interlocks compare only
  // the targets and the I/O with the last tick's, so only those are kept (a restored command is a quick
  // stop: its requests are set anew and it is on no move).
  for (std::size_t i = 0; i < n_axes_; ++i) {
    out.axes[i] = cmd_.axes[i];
    prev_cmd_.axes[i].target_position = cmd_.axes[i].target_position;
  }
  out.io = prev_cmd_.io = cmd_.io;
}

void Sequencer::sense(const hal::HalInputs& raw) noexcept {
  const hal::DigitalInputs& r = raw.io;
  const DualChannelSensors::Channels first = hal::safety_sensors(r);
  sensors_.update(first);
  second_channels_.update(r.second_channel);
  dual_.track(sensors_.values(), second_channels_.values());
  buttons_.update({r.button_start, r.button_pause, r.button_ack, r.row_knotted});
  // Everything below acts on the sensors as both channels agree (dual_channel.hpp), raw and debounced.
  raw_io_ = r;
  hal::set_safety_sensors(raw_io_, dual_.agreed(first, r.second_channel));
  io_ = r;
  hal::set_safety_sensors(io_, dual_.agreed(sensors_.values(), second_channels_.values()));
  io_.button_start = buttons_[0];
  io_.button_pause = buttons_[1];
  io_.button_ack = buttons_[2];
  io_.row_knotted = buttons_[3];
  // estop_ok is never filtered: an opened e-stop chain acts at once.
  if (sensed_ticks_ < 1000) ++sensed_ticks_;
}

bool Sequencer::check_faults(hal::Tick now, const hal::HalInputs& in) noexcept {
  if (all_quiet(now, in)) {
    load_cell_seen_ = load_cell_seen_ || in.analog.beat_force_valid;  // as the checks in order would note it
    return false;
  }
  return check_faults_in_order(now, in);
}

// Every condition check_faults_in_order() tests, or a wider one, in one pass and without a branch per
// condition (the flags are ORed): true only when none holds, so that the checks in order would latch
// nothing. On any flag the checks run in order, which decide the fault, its axis and its detail exactly as
// before; a wider condition only sends a tick there that finds nothing. The wider ones:
//  - staleness counts from the sample's tick alone: data never seen (kNeverTick, -1) looks older than
//    anything (now + 1), where the checks in order count it from arming (never older than that);
//  - a step is judged against one tick's allowance, with no exception for a re-based (homed) axis or the
//    first tick after idle, where the checks in order allow one per tick between samples (>= 1) and make
//    those exceptions; !(|step| <= limit) also flags a non-finite position (NaN or inf steps).
bool Sequencer::all_quiet(hal::Tick now, const hal::HalInputs& in) const noexcept {
  const hal::Tick stale = stale_ticks_;
  bool flag = !in.io.estop_ok | stop_now_requested_ | in.link.link_fault | (now - in.io.refreshed > stale);
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const hal::AxisFeedback& a = in.axes[i];
    flag |= a.fault | (a.state == DriveState::kFault) | (a.state == DriveState::kFaultReactionActive) |
            (enabled_outputs_ & !a.referenced) | (a.fault_kind != hal::FaultKind::kNone) |
            (now - a.refreshed > stale);
    // x - x is 0 for a finite x and NaN for inf or NaN; the sum is 0 only when both are finite.
    const bool finite_rest = (a.velocity - a.velocity) + (a.effort - a.effort) == 0.0;
    const bool small_step = std::abs(a.position - last(i).position) <= max_step_[i];
    flag |= !finite_rest | !small_step;
  }
  const double f = in.analog.beat_force_n;
  flag |= in.analog.beat_force_valid
              ? !(f - f == 0.0 && f >= -0.05 * cfg_.load_cell_max_n && f <= cfg_.load_cell_max_n)
              : load_cell_seen_;
  flag |= dual_.discrepant() >= 0;
  flag |= (sensed_ticks_ > cfg_.debounce_ticks) &
          ((io_.piston_a_extended & io_.piston_a_retracted) |
           (io_.piston_b_extended & io_.piston_b_retracted) | (io_.shuttle_at_left & io_.shuttle_at_right));
  return !flag;
}

bool Sequencer::check_faults_in_order(hal::Tick now, const hal::HalInputs& in) noexcept {
  if (!in.io.estop_ok) {
    latch(Fault::kEStop, now);
    return true;
  }
  if (stop_now_requested_) {
    latch(Fault::kStopRequested, now);
    return true;
  }
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const hal::AxisFeedback& a = in.axes[i];
    const int axis = static_cast<int>(i);
    if (drive_in_fault(a)) {
      latch(a.fault_kind == hal::FaultKind::kNodeLost ? Fault::kHeartbeatLost : Fault::kDriveFault, now, axis,
            a.fault_code);
      return true;
    }
    // A drive that powered up again has no reference: it must not move until homed at the next arming.
    if (enabled_outputs_ && !a.referenced) {
      latch(Fault::kAxisUnreferenced, now, axis, a.fault_code);
      return true;
    }
    // Any device fault stops motion in the same tick, even if the drive stays enabled (an EMCY).
    if (a.fault_kind != hal::FaultKind::kNone) {
      latch(a.fault_kind == hal::FaultKind::kNodeLost ? Fault::kHeartbeatLost : Fault::kDriveEmcy, now, axis,
            a.fault_code);
      return true;
    }
  }
  if (in.link.link_fault) {
    latch(in.link.link_fault_kind == hal::FaultKind::kNodeLost ? Fault::kHeartbeatLost : Fault::kLinkFault,
          now, -1, in.link.link_fault_code);
    return true;
  }
  // Data never seen counts as old as the time since arming: the first PDOs of a freshly started bus
  // legitimately arrive a few cycles after the first SYNC. Everything stale at once is the loop (or the
  // whole bus) stalling, not one device going quiet.
  const hal::Tick stale = stale_ticks_;
  const auto too_old = [&](hal::Tick refreshed) {
    return now - (refreshed == hal::kNeverTick ? armed_since_ : refreshed) > stale;
  };
  int stale_axis = -1, stale_count = 0;
  for (std::size_t i = 0; i < n_axes_; ++i) {
    if (too_old(in.axes[i].refreshed)) {
      if (stale_axis < 0) stale_axis = static_cast<int>(i);
      ++stale_count;
    }
  }
  const bool io_stale = too_old(in.io.refreshed);
  if (stale_count == static_cast<int>(n_axes_) && io_stale) {
    latch(Fault::kLoopStall, now);
    return true;
  }
  if (stale_axis >= 0 || io_stale) {
    latch(Fault::kStaleFeedback, now, stale_axis);
    return true;
  }
  // Feedback that cannot be true (fresh, but NaN/inf, or moved farther in one tick than the axis can).
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const hal::AxisFeedback& a = in.axes[i];
    if (!finite(a.position) || !finite(a.velocity) || !finite(a.effort)) {
      latch(Fault::kNonFiniteFeedback, now, static_cast<int>(i));
      return true;
    }
    // Compared sample to sample: feedback that arrived late comes in bursts (two samples in one tick
    // after none in the tick before), so the allowance is per tick between the samples' refresh ticks.
    const hal::AxisFeedback& was = last(i);
    const hal::Tick apart = a.refreshed != hal::kNeverTick && was.refreshed != hal::kNeverTick
                                ? std::max<hal::Tick>(1, a.refreshed - was.refreshed)
                                : 1;
    // A homing run that references the axis re-bases its reading once: that step is the reference, not a
    // jump.
    const bool rebased = a.referenced != was.referenced;
    if (positions_primed_ && !rebased &&
        std::abs(a.position - was.position) > max_step_[i] * static_cast<double>(apart)) {
      latch(Fault::kEncoderJump, now, static_cast<int>(i));
      return true;
    }
  }
  // The load cell, once fitted and seen, must keep reading a finite, plausible force.
  if (in.analog.beat_force_valid) {
    const double f = in.analog.beat_force_n;
    if (!finite(f) || f < -0.05 * cfg_.load_cell_max_n || f > cfg_.load_cell_max_n) {
      latch(Fault::kLoadCellFault, now);
      return true;
    }
    load_cell_seen_ = true;
  } else if (load_cell_seen_) {
    latch(Fault::kLoadCellFault, now);
    return true;
  }
  // Sensor pictures that no machine state can produce (once the debouncer has some history).
  if (const int sensor = dual_.discrepant(); sensor >= 0) {
    latch(Fault::kSensorDiscrepancy, now, -1, 0, sensor);
    return true;
  }
  if (sensed_ticks_ > cfg_.debounce_ticks) {
    if ((io_.piston_a_extended && io_.piston_a_retracted) ||
        (io_.piston_b_extended && io_.piston_b_retracted)) {
      latch(Fault::kShedSensorConflict, now);
      return true;
    }
    if (io_.shuttle_at_left && io_.shuttle_at_right) {
      latch(Fault::kShuttleSensorConflict, now);
      return true;
    }
  }
  return false;
}

bool Sequencer::is_symptom(Fault f) noexcept {
  return f == Fault::kStaleFeedback || f == Fault::kLoopStall || f == Fault::kCarriageInWarp ||
         f == Fault::kPickWithoutShed || f == Fault::kShedWithShuttle;
}

void Sequencer::refine_diagnosis(hal::Tick now, const hal::HalInputs& in) noexcept {
  if (!is_symptom(first_fault_) || now - fault_tick_ > diagnosis_ticks_) return;
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const hal::AxisFeedback& a = in.axes[i];
    if (drive_in_fault(a)) {
      first_fault_ = a.fault_kind == hal::FaultKind::kNodeLost ? Fault::kHeartbeatLost : Fault::kDriveFault;
      fault_axis_ = static_cast<int>(i);
      fault_detail_ = a.fault_code;
      add_fault_event(EventKind::kDiagnosisRefined);
      return;
    }
  }
  if (in.link.link_fault) {
    first_fault_ =
        in.link.link_fault_kind == hal::FaultKind::kNodeLost ? Fault::kHeartbeatLost : Fault::kLinkFault;
    fault_axis_ = -1;
    fault_detail_ = in.link.link_fault_code;
    add_fault_event(EventKind::kDiagnosisRefined);
  }
}

void Sequencer::report_presses() noexcept {
  // Reported, never acted on here: the owner turns each press into the request_*() call every other operator
  // path uses (operator_requests.hpp), so a command means one thing whatever station gave it.
  if (start_edge_.update(io_.button_start)) events_.add(EventKind::kButton).button = Button::kStart;
  if (pause_edge_.update(io_.button_pause)) events_.add(EventKind::kButton).button = Button::kPause;
  if (ack_edge_.update(io_.button_ack)) events_.add(EventKind::kButton).button = Button::kAck;
  if (knotted_edge_.update(io_.row_knotted)) events_.add(EventKind::kButton).button = Button::kRowKnotted;
}

void Sequencer::run_state(hal::Tick now, const hal::HalInputs& in) noexcept {
  switch (state_) {
    case State::kIdle:
      idle(now, in);
      break;
    case State::kEnabling:
      enabling(now, in);
      break;
    case State::kHoming:
      homing(now, in);
      break;
    case State::kPositioning:
      positioning(now, in);
      break;
    case State::kShedTest:
      shed_test(now);
      break;
    case State::kShed:
      shed(now);
      break;
    case State::kPick:
      pick(now, in);
      break;
    case State::kBeatSweep:
      beat_sweep(now);
      break;
    case State::kRowEnd:
      row_end(now);
      break;
    case State::kAwaitKnotting:
      await_knotting(now);
      break;
    case State::kKnotting:
      knotting(now, in);
      break;
    case State::kPaused:
      paused(now);
      break;
    case State::kDone:
      break;
    case State::kFault:
      fault(now);
      break;
  }
}

// ---------------------------------------------------------------------------------------------------
// One function per state
// ---------------------------------------------------------------------------------------------------

void Sequencer::idle(hal::Tick now, const hal::HalInputs& in) noexcept {
  request_all(cmd_, n_axes_, AxisRequest::kDisable);
  for (std::size_t i = 0; i < n_axes_; ++i) cmd_.axes[i].target_position = in.axes[i].position;
  // Valves hold the frames where the end sensors see them: starting up (or restarting after a power
  // loss) never moves a frame, so a shuttle left in the shed is never clamped.
  cmd_.io.piston_a_extend = io_.piston_a_extended;
  cmd_.io.piston_b_extend = io_.piston_b_extended;
  if (start_requested_) {
    start_requested_ = false;
    armed_since_ = now;
    enter(State::kEnabling, now);
  }
}

void Sequencer::enabling(hal::Tick now, const hal::HalInputs& in) noexcept {
  if (stop_requested_) {  // nothing has moved yet: the drives hold where they are
    enter(State::kDone, now);
    return;
  }
  request_all(cmd_, n_axes_, AxisRequest::kEnable);
  // The targets stay where idle left them, at the positions read when the start came: each drive enables
  // holding where its axis stands. They do not follow the readings while the drives enable: a drive enables
  // on the target of that tick, so a reading that lies then (an encoder glitch within the plausible step)
  // would become motion, with the frames wherever they are.
  bool all = true;
  for (std::size_t i = 0; i < n_axes_; ++i) all = all && in.axes[i].state == DriveState::kOperationEnabled;
  if (!all) {
    if (now - state_since_ > enable_timeout_ticks_) latch(Fault::kEnableTimeout, now);
    return;
  }
  begin_homing(now, in);
}

void Sequencer::begin_homing(hal::Tick now, const hal::HalInputs& in) noexcept {
  // Slot order is the machine's order: the beat crank first (its home point is clear of the warp), the
  // carriage once the beater is clear, then the added axes. The helix is never homed (absolute only).
  // A stop lets a homing run in progress finish (a drive's homing cut short leaves its axis unreferenced)
  // and starts no other.
  if (stop_requested_) {
    enter(State::kDone, now);
    return;
  }
  for (std::size_t i = 0; i < n_axes_; ++i) {
    if (in.axes[i].referenced) continue;
    if (cfg_.homing_timeout_s[i] <= 0.0) {  // unreferenced, and no homing run configured for it
      latch(Fault::kAxisUnreferenced, now, static_cast<int>(i));
      return;
    }
    if (i == index(CoreAxis::kCarriage) &&
        beater_in_warp(interlock_ctx_, in.axes[index(CoreAxis::kBeatCrank)].position)) {
      latch(Fault::kCarriageInWarp, now, static_cast<int>(i));
      return;
    }
    homing_axis_ = static_cast<int>(i);
    enter(State::kHoming, now);
    return;
  }
  homing_axis_ = -1;
  finish_arming(now, in);
}

void Sequencer::homing(hal::Tick now, const hal::HalInputs& in) noexcept {
  // The homing drive runs its homing by itself; its target follows its measured position so that nothing
  // jumps when it goes back to following targets. The other drives are enabled and hold their targets (a
  // target that followed their readings would turn a lying reading into motion).
  request_all(cmd_, n_axes_, AxisRequest::kEnable);
  const auto k = static_cast<std::size_t>(homing_axis_);
  cmd_.axes[k].target_position = in.axes[k].position;
  const hal::AxisFeedback& a = in.axes[k];
  if (a.referenced) {
    begin_homing(now, in);
    return;
  }
  if (a.homing_error || now - state_since_ > ticks(cfg_.homing_timeout_s[k])) {
    latch(Fault::kHomingFailed, now, homing_axis_);
    return;
  }
  cmd_.axes[k].request = AxisRequest::kHome;
}

void Sequencer::finish_arming(hal::Tick now, const hal::HalInputs& in) noexcept {
  // The counters are checked against the machine before anything moves: what they say was done must
  // be what the machine shows.
  if (!reconcile_at_arming(now, in)) return;
  enabled_outputs_ = true;
  knotters_parked_ = false;
  knot_park_planned_ = false;
  crank_parking_planned_ = false;  // positioning plans it once the knotting servos are at rest
  // Valves hold whatever the frames show now, so re-arming never moves a frame over the shuttle.
  cmd_.io.piston_a_extend = io_.piston_a_extended;
  cmd_.io.piston_b_extend = io_.piston_b_extended;
  enter(State::kPositioning, now);
}

bool Sequencer::knots_of_row_on_record() const noexcept {
  const KnotCounters& kc = counters_.knot;
  return knotter_.fitted() && kc.cycles_done >= static_cast<std::uint32_t>(cfg_.heads.program->stripe()) &&
         kc.cycles_started == kc.cycles_done;
}

double Sequencer::row_start_m() const noexcept {
  const bool heads_to_tie = knotter_.fitted() && !row_knotted_ && !knots_of_row_on_record();
  if (heads_to_tie && counters_.picks_in_row == 0) return 0.0;
  return sweep_starts_left() ? 0.0 : profiles_->carriage_travel_m();
}

void Sequencer::positioning(hal::Tick now, const hal::HalInputs& in) noexcept {
  // Re-arm from measured positions: the knotting servos to rest (nothing may cross a gripper left in the
  // warp), then the crank to the nearest park, then the carriage to the row's start side.
  if (!knotters_at_rest(now, in)) return;
  // A stop lets the re-arm move in progress finish and starts no other (the knotting servos' way back to
  // rest always finishes first: nothing may stand with a gripper in the warp).
  if (stop_requested_ && !crank_move_.active && !carriage_move_.active) {
    enter(State::kDone, now);
    return;
  }
  if (!crank_parking_planned_) {
    crank_parking_planned_ = true;
    const double phase =
        motion::wrap_pi(in.axes[index(CoreAxis::kBeatCrank)].position - cfg_.crank_park_position_rad);
    crank_move_ = {true, now, cmd_.axes[index(CoreAxis::kBeatCrank)].target_position,
                   motion::JerkMove::plan(-phase, profiles_->spec().crank)};
    return;
  }
  if (crank_move_.active || carriage_move_.active) return;
  // The carriage goes to where the row starts (a row cut mid-sweep is swept again from its start).
  const double rel = in.axes[index(CoreAxis::kCarriage)].position - cfg_.carriage_home_m;
  const double goal = row_start_m();
  if (std::abs(rel - goal) > cfg_.selvedge_tolerance_m) {
    carriage_move_ = {true, now, cmd_.axes[index(CoreAxis::kCarriage)].target_position,
                      motion::JerkMove::plan(goal - rel, cfg_.carriage)};
    return;
  }
  // Power lost mid-pick: the shuttle is in the open shed on its carrier. Finish that pick rather than
  // start a new one (nothing repeated, nothing lost); without an open shed it needs an operator.
  if (!shuttle_at_selvedge(io_)) {
    if (!shed_confirmed(io_)) {
      latch(Fault::kShuttleLost, now);
      return;
    }
    begin_pick(now, /*resumed=*/true);
    return;
  }
  if (counters_.picks_in_row >= cfg_.picks_per_row) {
    begin_sweep(now);
  } else if (counters_.picks_in_row == 0 && !row_.started()) {
    next_row(now);  // a fresh row: in knotting mode the weaver knots it first
  } else {
    begin_shed(now);
  }
}

bool Sequencer::knotters_at_rest(hal::Tick now, const hal::HalInputs& in) noexcept {
  // A knotting servo stopped inside its cycle (a power cut, a fault) goes back to the TAKE pose behind it
  // the way it came, grippers open, before the crank or the carriage moves: nothing crosses a gripper
  // left in the warp. Each servo moves on its own plan; the positioning waits for them all.
  if (!knotter_.fitted() || knotters_parked_) return true;
  bool moving = false;
  for (int h = 0; h < cfg_.heads.program->heads(); ++h) {
    const auto a = static_cast<std::size_t>(cfg_.heads.knotter_axis[static_cast<std::size_t>(h)]);
    ActiveMove& m = knot_park_[static_cast<std::size_t>(h)];
    if (!m.active && !knot_park_planned_) {
      // (A servo that trails its rest pose by a hair is at it, not a turn past the one behind.)
      const double rest = knotter_.rest_behind(in.axes[a].position + cfg_.heads.servo_tolerance_rad);
      const double from = cmd_.axes[a].target_position;
      if (std::abs(rest - from) > 1e-9) {
        m = {true, now, from, motion::JerkMove::plan(rest - from, knot_park_limits_)};
      }
    }
    if (!m.active) continue;
    const double t = seconds_since(now, m.t0);
    cmd_.axes[a].target_position = m.origin + m.move.position_at(t);
    if (t >= m.move.duration()) m.active = false;
    moving |= m.active;
  }
  knot_park_planned_ = true;
  if (moving) return false;
  knotters_parked_ = true;
  return true;
}

void Sequencer::shed_test(hal::Tick now) noexcept {
  // Four strokes — A up, B up, A up, B up — move each frame both ways twice: every end sensor is seen to
  // switch off and on (a stuck one is found now, not under a pick), every stroke time is learned, and
  // every learned time is checked by a later stroke (a sensor sticking on during the learning stroke
  // never lets go on the next one), so the first pick's shed is judged against proven stroke times.
  const ShedVerdict v = shed_.update(profiles_->shed(), seconds_since(now, state_since_), ends_a(), ends_b());
  if (is_fault(v)) {
    latch(shed_fault(v), now);
    return;
  }
  if (v != ShedVerdict::kOpen) return;
  if (stop_requested_) {  // between two strokes: the test runs again in full at the next start
    enter(State::kDone, now);
    return;
  }
  if (++shed_test_step_ < kShedTestStrokes) {
    const bool a_up = shed_test_step_ % 2 == 0;
    start_stroke(a_up, !a_up);
    state_since_ = now;
    return;
  }
  sensors_proven_ = true;
  begin_shed(now);
}

void Sequencer::shed(hal::Tick now) noexcept {
  // The end sensors must show a consistent, plausible picture (ShedMonitor), then the frames settle.
  const ShedVerdict v = shed_.update(profiles_->shed(), seconds_since(now, state_since_), ends_a(), ends_b());
  if (is_fault(v)) {
    latch(shed_fault(v), now);
    return;
  }
  if (v != ShedVerdict::kOpen) return;
  if (!shuttle_where_counters_say(now)) return;
  row_.add_shed(now - phase_start_);
  begin_pick(now, /*resumed=*/false);
}

void Sequencer::pick(hal::Tick now, const hal::HalInputs& in) noexcept {
  const bool arrived = pick_to_right_ ? io_.shuttle_at_right : io_.shuttle_at_left;
  const bool raw_arrived = pick_to_right_ ? raw_io_.shuttle_at_right : raw_io_.shuttle_at_left;
  const bool still_at_start = pick_to_right_ ? io_.shuttle_at_left : io_.shuttle_at_right;
  // Where the carrier really is. The shuttle rides it: the start sensor must let go when the carrier
  // leaves its reach, the arrival sensor see the shuttle when the carrier enters its reach — not before
  // (a stuck or miswired sensor), not after (the shuttle slipped off and a sensor lies or sticks).
  const double lead = profiles_->spec().helix_lead_m;
  const double helix = in.axes[index(CoreAxis::kHelix)].position;
  const double to_goal_m = std::abs(helix - pick_goal_rad_) * lead / motion::kTwoPi;
  const double from_start_m = std::abs(helix - pick_start_rad_) * lead / motion::kTwoPi;
  const double reach = cfg_.selvedge_sensor_window_m, tol = cfg_.shuttle_follow_tolerance_m;
  // Sensors and positions are samples. An edge is seen at the first sample after it happened, so the
  // carrier may have gone up to one tick's travel past the switching point unseen; and when the I/O
  // node's inputs and the helix drive's position were refreshed on different ticks, they describe the
  // carrier up to that many ticks apart. The windows below widen by exactly these amounts (at 2 ms on
  // a synchronous bus: ~2 mm; at 20 ms, ten times that), instead of assuming one loop period.
  carrier_prev_step_m_ = carrier_step_m_;
  carrier_step_m_ = std::abs(helix - prev_helix_rad_) * lead / motion::kTwoPi;
  prev_helix_rad_ = helix;
  const hal::Tick io_at = in.io.refreshed, helix_at = in.axes[index(CoreAxis::kHelix)].refreshed;
  const hal::Tick skew_ticks = io_at == hal::kNeverTick || helix_at == hal::kNeverTick
                                   ? 0
                                   : (io_at > helix_at ? io_at - helix_at : helix_at - io_at);
  const double skew_m = static_cast<double>(std::min<hal::Tick>(skew_ticks, cfg_.debounce_ticks + 1)) *
                        std::max(carrier_step_m_, carrier_prev_step_m_);
  if (!pick_resumed_) {
    if (carrier_left_ == hal::kNeverTick && from_start_m > reach + tol + skew_m) carrier_left_ = now;
    if (carrier_left_ != hal::kNeverTick && still_at_start &&
        now - carrier_left_ > cfg_.debounce_ticks + 1 + skew_ticks) {
      latch(Fault::kShuttleSlipped, now);
      return;
    }
  }
  if (to_goal_m <= reach && carrier_at_selvedge_ == hal::kNeverTick) carrier_at_selvedge_ = now;
  if (raw_arrived && raw_arrival_at_m_ < 0.0 && to_goal_m <= reach + kArrivalMarginM + skew_m) {
    raw_arrival_at_m_ = to_goal_m;
    raw_arrival_lateness_m_ = carrier_step_m_ + skew_m;
  }
  if (!raw_arrived && !arrived && to_goal_m > reach)
    raw_arrival_at_m_ = -1.0;  // a bounce before the carrier came
  if (arrived && to_goal_m > reach + kArrivalMarginM + skew_m) {
    latch(Fault::kShuttleSensorEarly, now);
    return;
  }
  // The arrival edge must come as the carrier crosses the switching point: well before it the shuttle
  // cannot be there (unless it ran ahead, off its carrier); well after it, it did not come with it.
  if (arrived && raw_arrival_at_m_ >= 0.0 &&
      (raw_arrival_at_m_ < reach - tol - raw_arrival_lateness_m_ ||
       raw_arrival_at_m_ > reach + 0.25 * tol + skew_m)) {
    latch(Fault::kShuttleSlipped, now);
    return;
  }
  if (arrived && !helix_move_.active) {
    ++counters_.picks;
    ++counters_.picks_in_row;
    events_.add(EventKind::kPick);
    row_.add_pick(now - phase_start_);
    if (counters_.picks_in_row < cfg_.picks_per_row) {
      if (!hold_here(now)) begin_shed(now);
    } else {
      begin_sweep(now);
    }
    return;
  }
  const bool missed = !arrived && carrier_at_selvedge_ != hal::kNeverTick &&
                      now - carrier_at_selvedge_ > cfg_.debounce_ticks + arrival_grace_ticks_;
  if (missed ||
      seconds_since(now, state_since_) > profiles_->pick().duration() + cfg_.pick_timeout_margin_s) {
    latch(Fault::kShuttleNotArrived, now);
  }
}

void Sequencer::beat_sweep(hal::Tick now) noexcept {
  if (!crank_move_.active) end_row(now);
}

void Sequencer::paused(hal::Tick now) noexcept {
  // A stop leaves a paused loom standing: it ends the run where it holds (the next run resumes the row, its
  // picks or its knots, from the counters), never by finishing the row first.
  if (stop_requested_) {
    paused_in_knotting_ = false;
    enter(State::kDone, now);
    return;
  }
  if (pause_requested_) return;
  // Resumed: paused between two knot cycles goes on knotting; between the picks of a row resumes that row;
  // at a row's end starts the next.
  if (paused_in_knotting_) {
    paused_in_knotting_ = false;
    enter(State::kKnotting, now);
    return;
  }
  row_.started() ? begin_shed(now) : next_row(now);
}

void Sequencer::fault(hal::Tick now) noexcept {
  if (!ack_requested_) return;
  ack_requested_ = false;
  // Refused while the cause persists: an open e-stop chain keeps the fault latched (red lamp, quick stop)
  // instead of going idle and re-latching at the next start. (Link causes: the runner refuses those.)
  if (!io_.estop_ok) return;
  // Acknowledged: the drives get their fault-reset edge this tick, then the machine idles disabled and
  // re-arms from measured positions on the next start, proving the sensors again.
  first_fault_ = stopped_by_ = Fault::kNone;
  fault_axis_ = fault_sensor_ = -1;
  fault_detail_ = 0;
  fault_tick_ = hal::kNeverTick;
  stop_now_requested_ = false;
  enabled_outputs_ = false;
  sensors_proven_ = false;
  load_cell_seen_ = false;
  shed_.forget_stroke_times();
  acknowledged_this_tick_ = true;
  enter(State::kIdle, now);
}

// ---------------------------------------------------------------------------------------------------
// Transitions
// ---------------------------------------------------------------------------------------------------

bool Sequencer::reconcile_at_arming(hal::Tick now, const hal::HalInputs& in) noexcept {
  const KnotCounters& k = counters_.knot;
  const bool knots_impossible =
      k.cycles_done > k.cycles_started ||
      (knotter_.fitted() && k.cycles_started > static_cast<std::uint32_t>(cfg_.heads.program->stripe()));
  if (counters_.picks_in_row > cfg_.picks_per_row || counters_.picks_in_row > counters_.picks ||
      knots_impossible) {
    latch(Fault::kCountersInconsistent, now);
    return false;
  }
  if (!shuttle_at_selvedge(io_) || io_.shuttle_at_left == expect_shuttle_left()) return true;
  // The shuttle is on the side the counters say it left. Only one story fits that and is safe to
  // continue: pick N completed just before a power loss and its count never reached the file. Then the
  // shed is still open for pick N and the row's beat sweep has not begun (the carriage waits at the row's
  // start side). Anything else — a reset or missing counters file, a machine moved by hand — would make
  // the next beat a beat without weft: refuse, the operator checks the cloth and the counters.
  const bool a_up = counters_.picks % 2 == 0;
  const bool shed_of_pick_n = shed_confirmed(io_) && io_.piston_a_extended == a_up;
  const double rel = in.axes[index(CoreAxis::kCarriage)].position - cfg_.carriage_home_m;
  const double start = sweep_starts_left() ? 0.0 : profiles_->carriage_travel_m();
  const bool before_sweep = std::abs(rel - start) <= cfg_.selvedge_tolerance_m;
  if (counters_.picks_in_row < cfg_.picks_per_row && shed_of_pick_n && before_sweep) {
    ++counters_.picks;
    ++counters_.picks_in_row;
    events_.add(EventKind::kPick);  // the pick whose count never reached the file: counted now
    return true;
  }
  latch(Fault::kShuttleSideMismatch, now);
  return false;
}

bool Sequencer::shuttle_where_counters_say(hal::Tick now) noexcept {
  // Before every pick: the shuttle must be at exactly the selvedge the counters say (it starts at the
  // left; every pick alternates). Never pick from, or count a pick at, the wrong side.
  if (!shuttle_at_selvedge(io_)) {
    latch(Fault::kShuttleLost, now);
    return false;
  }
  if (io_.shuttle_at_left != expect_shuttle_left()) {
    latch(Fault::kShuttleSideMismatch, now);
    return false;
  }
  return true;
}

void Sequencer::begin_row(hal::Tick now) noexcept {
  if (slot_ != nullptr && slot_->swap_at_row_boundary()) {
    // A new recipe: its warp window guards the interlocks from now on, and the machine re-arms from
    // its measured positions (crank to park, carriage to a selvedge of the new width) before the row.
    profiles_ = &slot_->active();
    interlock_ctx_.warp = &profiles_->beatup().warp();
    adopt_limits();
    ++recipe_changes_;
    enter(State::kPositioning, now);
    return;
  }
  begin_shed(now);
}

void Sequencer::begin_shed(hal::Tick now) noexcept {
  row_.begin(counters_.rows + 1, now);
  row_knotted_ = false;       // the row is under way: the next one needs its own knotting
  if (knotting_ticks_ > 0) {  // the weaver's knotting before this row, recorded with it
    row_.set_knotting(knotting_ticks_);
    knotting_ticks_ = 0;
  }
  // The shed may only change with the shuttle out of it, at the side the counters expect.
  if (!shuttle_where_counters_say(now)) return;
  if (!sensors_proven_) {  // the first shed change since arming: prove the end sensors first
    shed_test_step_ = 0;
    start_stroke(true, false);
    enter(State::kShedTest, now);
    return;
  }
  // Alternate the shed every pick: even picks lift frame A, odd picks frame B.
  const bool a_up = counters_.picks % 2 == 0;
  start_stroke(a_up, !a_up);
  phase_start_ = now;
  enter(State::kShed, now);
}

void Sequencer::start_stroke(bool a_extend, bool b_extend) noexcept {
  cmd_.io.piston_a_extend = a_extend;
  cmd_.io.piston_b_extend = b_extend;
  shed_.start(a_extend, b_extend, ends_a(), ends_b());
}

void Sequencer::begin_pick(hal::Tick now, bool resumed) noexcept {
  row_.begin(counters_.rows + 1, now);
  // The shuttle goes away from the side the counters say it started at.
  pick_to_right_ = expect_shuttle_left();
  const double from = cmd_.axes[index(CoreAxis::kHelix)].target_position;
  if (resumed) {
    // A pick cut by a power loss: the carrier is somewhere in the shed; finish at the far selvedge.
    pick_goal_rad_ = cfg_.helix_left_position_rad + (pick_to_right_ ? profiles_->pick().distance() : 0.0);
    helix_move_ = {true, now, from, motion::JerkMove::plan(pick_goal_rad_ - from, profiles_->helix_limits())};
  } else {
    // The goal is the far selvedge's own position, not `from` + the pick's distance: after a power cut in
    // the first or last ticks of a pick the shuttle is still (or already) at a selvedge while the carrier
    // stands a few millimetres off it, and a relative goal would carry that offset into the arrival check
    // (a false shuttle_slipped). Off the selvedge, the carrier goes straight to the goal (bounded move).
    const double start_rad =
        cfg_.helix_left_position_rad + (pick_to_right_ ? 0.0 : profiles_->pick().distance());
    pick_goal_rad_ = cfg_.helix_left_position_rad + (pick_to_right_ ? profiles_->pick().distance() : 0.0);
    const double off_m = std::abs(from - start_rad) * profiles_->spec().helix_lead_m / motion::kTwoPi;
    if (off_m <= kCarrierAtSelvedgeM) {
      helix_move_ = {true, now, from, pick_to_right_ ? profiles_->pick() : profiles_->pick_back()};
    } else {
      helix_move_ = {true, now, from,
                     motion::JerkMove::plan(pick_goal_rad_ - from, profiles_->helix_limits())};
    }
  }
  carrier_at_selvedge_ = hal::kNeverTick;
  carrier_left_ = hal::kNeverTick;
  raw_arrival_at_m_ = -1.0;
  raw_arrival_lateness_m_ = 0.0;
  prev_helix_rad_ = from;
  carrier_step_m_ = carrier_prev_step_m_ = 0.0;
  pick_start_rad_ = from;
  pick_resumed_ = resumed;
  phase_start_ = now;
  enter(State::kPick, now);
}

void Sequencer::begin_sweep(hal::Tick now) noexcept {
  row_.begin(counters_.rows + 1, now);  // resumed after a restart with every pick of the row done
  // The crank turns `beats` full turns from park; the carriage rides the cam on it from the row's sweep
  // start (row_sweep_starts_left) across to the other selvedge.
  carriage_sweep_dir_ = sweep_starts_left() ? 1.0 : -1.0;
  carriage_sweep_origin_ = cmd_.axes[index(CoreAxis::kCarriage)].target_position;
  crank_sweep_origin_ = cmd_.axes[index(CoreAxis::kBeatCrank)].target_position;
  crank_move_ = {true, now, crank_sweep_origin_, profiles_->crank_sweep()};
  sweep_clock_.start(now);
  if (regulator_.enabled()) sweep_clock_.request(0, regulator_.first_beat(beat_position(0)));
  sweeping_ = true;
  row_beats_ = 0;
  beats_published_ = 0;
  sweep_start_ = now;
  enter(State::kBeatSweep, now);
}

void Sequencer::end_row(hal::Tick now) noexcept {
  sweeping_ = false;
  sweep_clock_.stop();
  while (beats_published_ < row_beats_) publish_beat(beats_published_);
  ++counters_.rows;
  counters_.picks_in_row = 0;
  // The row's knots from the counters' tallies of the row in progress: whole even when a power cut came
  // after (or in) its knotting, whose RowKnots then started again from the restart.
  if (knotter_.fitted()) {
    const KnotCounters& k = counters_.knot;
    row_.set_knot_counts(static_cast<int>(k.row_tied), static_cast<int>(k.row_retried),
                         static_cast<int>(k.row_by_hand));
  }
  last_row_ = row_.finish(now, now - sweep_start_, row_beats_, profiles_->cam().steps());
  events_.add(EventKind::kRow);
  KnotCounters& k = counters_.knot;
  if (k.cycles_started != 0 || k.cycles_done != 0 || k.row_tied != 0 || k.row_retried != 0 ||
      k.row_by_hand != 0) {
    k.cycles_started = k.cycles_done = 0;  // the next row's knotting starts afresh
    k.row_tied = k.row_retried = k.row_by_hand = 0;
    events_.add(EventKind::kKnotProgress);
  }
  if (cfg_.await_row_saved) {
    enter(State::kRowEnd, now);
    return;
  }
  after_row(now);
}

void Sequencer::row_end(hal::Tick now) noexcept {
  // Parked at the boundary (beater out of the warp, shuttle at a selvedge): the next row waits for
  // the reporter to confirm that the finished one is on disk; a failed or unconfirmed save stops here.
  if (rows_on_disk_ >= counters_.rows) {
    after_row(now);
    return;
  }
  if (last_save_failed_ || seconds_since(now, state_since_) > cfg_.row_save_timeout_s) {
    latch(Fault::kCountersNotSaved, now);
  }
}

void Sequencer::after_row(hal::Tick now) noexcept {
  const bool enough = cfg_.rows_to_weave != 0 && counters_.rows >= cfg_.rows_to_weave;
  if (enough) {
    enter(State::kDone, now);
  } else if (!hold_here(now)) {
    next_row(now);
  }
}

void Sequencer::next_row(hal::Tick now) noexcept {
  if (!row_knotted_ && knots_of_row_on_record()) {
    row_knotted_ = true;  // every knot of this row was tied before a restart: on to its shed
  }
  if (knotter_.fitted() && !row_knotted_) {
    // The heads tie the row (from the counters' progress: a row cut by a power loss resumes at its first
    // knot not known to be tied); the carriage then goes to the row's sweep start.
    row_.begin(counters_.rows + 1, now);
    knotter_requests_seen_ = knotter_.requests();
    knot_requested_ = false;
    knotter_.begin(counters_.rows, counters_.knot, sweep_starts_left() ? 0.0 : profiles_->carriage_travel_m(),
                   now, cmd_);
    if (knotter_.requests() != knotter_requests_seen_) events_.add(EventKind::kWeaverRequest);
    enter(State::kKnotting, now);
    return;
  }
  if (cfg_.knotting && !row_knotted_) {
    knot_requested_ = false;  // a pedal press from before the row was woven does not count for the next
    enter(State::kAwaitKnotting, now);
    return;
  }
  begin_row(now);  // (a recipe swapped here re-arms first and comes back through next_row, still knotted)
}

void Sequencer::await_knotting(hal::Tick now) noexcept {
  // Parked (beater out of the warp, shuttle at a selvedge, drives enabled and holding) while the weaver
  // knots the row; a stop goes to done from here, a pause simply waits with it.
  if (stop_requested_) {
    enter(State::kDone, now);
    return;
  }
  if (!knot_requested_) return;
  knot_requested_ = false;
  row_knotted_ = true;
  knotting_ticks_ = now - state_since_;
  next_row(now);
}

void Sequencer::knotting(hal::Tick now, const hal::HalInputs& in) noexcept {
  // The heads work between the warp threads: the shed must stay where it is the whole time (the interlock
  // would refuse the next knot; this names the cause first).
  if (!shed_still(io_)) {
    latch(Fault::kShedLost, now);
    return;
  }
  // A new request of the weaver: a pedal press from before it does not answer it.
  if (knotter_.requests() != knotter_requests_seen_) {
    knotter_requests_seen_ = knotter_.requests();
    knot_requested_ = false;
  }
  RowKnotter::StepInputs ks;
  ks.weaver_done = knot_requested_;
  ks.hold = stop_requested_ || pause_requested_;
  ks.await_disk = cfg_.await_row_saved;
  ks.on_disk_started = knots_on_disk_rows_ == counters_.rows ? knots_on_disk_started_ : 0;
  ks.disk_timeout_ticks = row_save_timeout_ticks_;
  const std::uint32_t requests_before = knotter_.requests();
  const RowKnotter::Status st = knotter_.step(now, in, cmd_, counters_.knot, ks);
  // The heads report what their step did: their counters moved, a request made of the weaver.
  if (knotter_.counters_moved()) events_.add(EventKind::kKnotProgress);
  if (knotter_.requests() != requests_before) events_.add(EventKind::kWeaverRequest);
  knot_requested_ = false;  // answered the request, or came when none was open
  switch (st) {
    case RowKnotter::Status::kRunning:
      return;
    case RowKnotter::Status::kHeld:
      // Between two knot cycles, the heads at rest: a stop ends the run here, a pause holds here (resume
      // goes on knotting); the next run after a stop begins this cycle afresh.
      if (hold_here(now) && state_ == State::kPaused) paused_in_knotting_ = true;
      return;
    case RowKnotter::Status::kAwaitingWeaver:
      // Parked for the weaver, the heads at rest: a stop ends here, as it does while the weaver knots a row
      // in weaver mode (the next run resumes the row at its first knot not known to be tied).
      if (stop_requested_) enter(State::kDone, now);
      return;
    case RowKnotter::Status::kFault:
      latch(knotter_.fault(), now, knotter_.fault_axis());
      return;
    case RowKnotter::Status::kDone: {
      const RowKnots& k = knotter_.row();
      row_.set_knots(k.ticks, k.weaver_ticks, k.tied, k.retried, k.by_hand);
      row_knotted_ = true;
      // A stop or pause asked for as the last cycle ended holds here, before the row's shed (resume sheds
      // it).
      if (!hold_here(now)) next_row(now);
      return;
    }
  }
}

Fault Sequencer::shed_fault(ShedVerdict v) const noexcept {
  switch (v) {
    case ShedVerdict::kTooEarly:
      return Fault::kShedSensorEarly;
    case ShedVerdict::kTooLate:
      return Fault::kShedSensorLate;
    case ShedVerdict::kNotReleased:
      return Fault::kShedNotReleased;
    case ShedVerdict::kAirLost:
      return Fault::kAirLost;
    case ShedVerdict::kConflict:
      return Fault::kShedSensorConflict;
    case ShedVerdict::kTimeout:
      return Fault::kShedTimeout;
    case ShedVerdict::kMoving:
    case ShedVerdict::kSettling:
    case ShedVerdict::kOpen:
      break;
  }
  return Fault::kNone;
}

// ---------------------------------------------------------------------------------------------------
// Outputs
// ---------------------------------------------------------------------------------------------------

void Sequencer::play_moves(hal::Tick now) noexcept {
  const auto play = [&](ActiveMove& m, CoreAxis axis) {
    if (!m.active) return;
    const double t = seconds_since(now, m.t0);
    cmd_.axes[index(axis)].target_position = m.origin + m.move.position_at(t);
    if (t >= m.move.duration()) m.active = false;
  };
  // The crank's move is sampled once: as a move of its own and, in the sweep, as the master phase — at
  // the sweep clock's time, warped by the beat regulator's speeds (the tick time while there are none).
  // (active() only in a sweep: the clock is stopped with it.)
  const double sweep_t =
      sweep_clock_.active() ? sweep_clock_.time_at(now) : seconds_since(now, crank_move_.t0);
  const bool crank_played = crank_move_.active;
  const double crank_offset = crank_played || sweeping_ ? crank_move_.move.position_at(sweep_t) : 0.0;
  if (crank_played) {
    cmd_.axes[index(CoreAxis::kBeatCrank)].target_position = crank_move_.origin + crank_offset;
    if (sweep_t >= crank_move_.move.duration()) crank_move_.active = false;
  }
  play(carriage_move_, CoreAxis::kCarriage);
  play(helix_move_, CoreAxis::kHelix);
  if (!sweeping_) return;
  // The sweep move is the master phase; the crank follows the speed law (constant: the same). A speed
  // change the regulator asked for starts once the master is inside its window (carriage at rest); this
  // tick's targets are sampled already, it acts from the next.
  if (sweep_clock_.active()) sweep_clock_.advance(now, crank_offset);
  const motion::Phase master = motion::Phase::from_rad(crank_offset);
  const double phi = profiles_->crank_phase_at(master);
  cmd_.axes[index(CoreAxis::kBeatCrank)].target_position = crank_sweep_origin_ + phi;
  cmd_.axes[index(CoreAxis::kCarriage)].target_position =
      carriage_sweep_origin_ + carriage_sweep_dir_ * profiles_->cam().position_at(phi);
  // A beat is delivered when the commanded crank passes the fell of turn k.
  const double fell = profiles_->beatup().warp().fell;
  while (row_beats_ < profiles_->beats_per_row() && phi >= motion::kTwoPi * row_beats_ + fell) {
    row_.beat_at(row_beats_, cmd_.axes[index(CoreAxis::kCarriage)].target_position - cfg_.carriage_home_m);
    ++row_beats_;
    ++counters_.beats;
  }
  // A counted beat is published once the beater has left the warp (its peak force is final then).
  const double exit = profiles_->beatup().warp().exit;
  while (beats_published_ < row_beats_ && phi >= motion::kTwoPi * beats_published_ + exit) {
    publish_beat(beats_published_);
  }
}

void Sequencer::track_beat_force(const hal::HalInputs& in) noexcept {
  if (!sweeping_ || !in.analog.beat_force_valid) return;
  // Beat k is the k-th passage through the warp; its peak is recorded while the beater is in the warp.
  const double crank = in.axes[index(CoreAxis::kBeatCrank)].position;
  const double phi = crank - crank_sweep_origin_;
  const int k = static_cast<int>(std::floor(phi / motion::kTwoPi));
  if (k < 0 || k >= profiles_->beats_per_row()) return;
  if (!beater_in_warp(interlock_ctx_, crank)) return;
  row_.force(k, in.analog.beat_force_n);
}

void Sequencer::publish_beat(int k) noexcept {
  BeatEvent& e = events_.add(EventKind::kBeat).beat;
  e.row = counters_.rows + 1;
  e.index = static_cast<std::uint16_t>(k);
  const RowStats& r = row_.stats();
  if (k < kMaxBeatsPerRow) {
    const BeatRecord& b = r.beat[static_cast<std::size_t>(k)];
    e.x_m = b.x_m;
    e.peak_force_n = b.peak_force_n;
  }
  e.force_measured = r.force_measured;
  e.in_band =
      e.force_measured && e.peak_force_n >= cfg_.beat_force_min_n && e.peak_force_n <= cfg_.beat_force_max_n;
  // The speed it was beaten at (the clock is back at the recipe's by now; the next beat's is asked below).
  e.speed_scale = static_cast<float>(sweep_clock_.beat_scale());
  row_.speed(k, e.speed_scale);
  beats_published_ = k + 1;
  if (e.force_measured && sweeping_ && regulator_.enabled())
    regulate_after(k, e);  // a load cell: closed loop
}

int Sequencer::beat_position(int k) const noexcept {
  const int per = std::max(1, profiles_->spec().beats_per_position);
  const int i = k / per, positions = profiles_->beats_per_row() / per;
  return carriage_sweep_dir_ > 0.0 ? i : positions - 1 - i;
}

// Beat k is final (the beater has left the warp): the regulator learns from it and chooses the next
// beat's speed, which the sweep clock plays in that beat's window; after the last beat, back to the
// recipe's speed before the braking. Per beat, never per tick.
void Sequencer::regulate_after(int k, const BeatEvent& e) noexcept {
  const int next = k + 1;
  const bool last = next >= profiles_->beats_per_row();
  const double s =
      regulator_.after_beat(beat_position(k), e.speed_scale, e.force_measured && e.peak_force_n > 0.0f,
                            e.peak_force_n, last ? -1 : beat_position(next));
  sweep_clock_.request(next, s);
}

void Sequencer::signal() noexcept {
  // Stack light: red = a fault waits for acknowledgement; green = weaving; amber = waiting for the
  // operator (idle, arming, paused, done).
  const bool asking = state_ == State::kKnotting && knotter_.request().ask != WeaverAsk::kNone;
  const bool weaving = state_ == State::kHoming || state_ == State::kPositioning ||
                       state_ == State::kShedTest || state_ == State::kShed || state_ == State::kPick ||
                       state_ == State::kBeatSweep || state_ == State::kRowEnd ||
                       (state_ == State::kKnotting && !asking);
  cmd_.io.lamp_red = state_ == State::kFault;
  cmd_.io.lamp_green = weaving;
  cmd_.io.lamp_amber = !weaving && state_ != State::kFault;
  cmd_.io.buzzer = asking;  // the weaver is needed at the machine (a knot to tie by hand, a slot to reload)
}

}  // namespace loom::sequencer
