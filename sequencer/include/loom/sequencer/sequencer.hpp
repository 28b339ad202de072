// The row cycle as a pure per-tick step: shed change → pick → beat sweep → row done, with the
// interlocks, fault latching and production counters. No clock, no I/O: the tick index comes in, the
// commands go out, so tests run it in virtual time. All motion comes from the precomputed ProfileSet.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "loom/hal/types.hpp"
#include "loom/motion/jerk_move.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/motion/profile_slot.hpp"
#include "loom/sequencer/beat_regulator.hpp"
#include "loom/sequencer/debounce.hpp"
#include "loom/sequencer/dual_channel.hpp"
#include "loom/sequencer/faults.hpp"
#include "loom/sequencer/interlocks.hpp"
#include "loom/sequencer/row_knotter.hpp"
#include "loom/sequencer/row_stats.hpp"
#include "loom/sequencer/shed_monitor.hpp"
#include "loom/sequencer/tick_events.hpp"

namespace loom::sequencer {

enum class State : std::uint8_t {
  kIdle,         // drives disabled, waiting for start
  kEnabling,     // walking the drives to Operation Enabled
  kHoming,       // referencing the axes whose drives powered up unreferenced, one at a time, in machine order
  kPositioning,  // re-arm: crank to park, carriage to the row's start selvedge, from measured positions
  kShedTest,     // proving the end sensors: each frame stroked both ways twice before the first pick
  kShed,         // swapping the heald frames, waiting for a consistent end-sensor picture
  kPick,         // helix shaft carries the shuttle across, waiting for arrival
  kBeatSweep,    // crank beats while the carriage steps across the width
  kRowEnd,       // row woven, beater parked: waiting until its counters are on disk (when asked to)
  kAwaitKnotting,  // knotting mode: parked before a new row until the weaver says the row is knotted
  kKnotting,       // knotting heads: tying the row knot by knot before its shed change (or asking the weaver)
  kPaused,         // holding at a safe point (before a shed change), drives enabled, until resumed
  kDone,           // all requested rows woven, or stopped at a hold point: holding, enabled
  kFault,          // latched fault: quick stop, valves hold, counters kept
};
const char* state_name(State s);

struct Counters {
  std::uint32_t rows = 0;          // completed rows
  std::uint32_t picks = 0;         // completed picks (shuttle arrived)
  std::uint32_t beats = 0;         // beats delivered (beater passed the fell)
  std::uint32_t picks_in_row = 0;  // picks of the row in progress (restart resumes here)
  KnotCounters knot{};             // knotting heads: knots tied/retried/by hand, the row's cycles
};

struct SequencerConfig {
  double period_s = 0.002;
  // The machine's axes (the core three at slots 0..2, then what the machine adds); every axis is enabled,
  // supervised (drive fault, EMCY, staleness, non-finite or jumping feedback) and stopped with the loom.
  hal::AxisLayout axes = hal::AxisLayout::core();
  // Top speed of each added axis (slot 3 on; SI/s): bounds the feedback's plausible step per tick. The
  // core axes' come from the profiles.
  std::array<double, hal::kMaxAxes> axis_max_speed{};
  // Per axis: how long a homing run may take (s); 0 for an absolute axis (never homed). An axis the HAL
  // reports unreferenced is homed when the loom arms, beat crank first (its home point is clear of the
  // warp), then the carriage, then the added axes; it never moves in production unreferenced.
  std::array<double, hal::kMaxAxes> homing_timeout_s{};
  std::uint32_t rows_to_weave = 3;  // 0 = weave until stopped (absolute row count to reach)
  std::uint32_t picks_per_row = 1;  // weft picks (each with its own shed change) before the beat sweep
  int debounce_ticks = 3;           // a sensor must read the same this many ticks to count (not e-stop)
  // Which safety sensors have a second channel (hal::SafetySensor order; see dual_channel.hpp), and how
  // long (after each channel's debounce) the two may disagree before that is the fault sensor_discrepancy
  // (never less than debounce_ticks + 1 ticks).
  std::array<bool, hal::kSafetySensorCount> second_channel{};
  double sensor_discrepancy_s = 0.02;
  double enable_timeout_s = 2.0;
  double pick_timeout_margin_s = 0.5;  // beyond the planned pick duration
  double stale_timeout_s = 0.05;       // feedback older than this is a fault
  // After motion stops on a symptom (stale feedback, an interlock trip), a root cause reported within
  // this window (a drive fault, a lost heartbeat) becomes the first fault. Set it to the heartbeat
  // consumer time plus a few periods on CAN, so a dead drive is reported as such, not as its symptom.
  double diagnosis_window_s = 0.3;
  double crank_park_position_rad = 0.0;  // crank axis reading at the park pose (calibration)
  double carriage_home_m = 0.0;          // carriage axis reading at the left selvedge
  double helix_left_position_rad = 0.0;  // helix axis reading with the carrier at the left selvedge
  double park_tolerance_rad = 0.01;
  double selvedge_tolerance_m = 0.001;
  // The shuttle-arrival sensors see the shuttle within this distance of their selvedge (machine wiring).
  // An arrival seen while the carrier is farther away than this (plus 2 mm) is a sensor fault; an arrival
  // not seen within arrival_grace_s (plus the debounce) of the carrier entering it is a lost shuttle.
  double selvedge_sensor_window_m = 0.005;
  double arrival_grace_s = 0.02;
  // The shuttle moves with its carrier: its start sensor must go off, and its arrival sensor come on, when
  // the carrier passes the sensor's switching point, within this distance (the sensors' switching-point
  // spread). A shuttle that lags its carrier by more has slipped off the magnet.
  double shuttle_follow_tolerance_m = 0.002;
  double beat_force_min_n = 80.0;  // the band every beat must hit (thesis: 80–100 N)
  double beat_force_max_n = 100.0;
  // The per-beat regulator (beat_regulator.hpp): from each measured beat it sets the next beat's crank
  // speed, aiming at the band's middle. It acts only on measured beats: a loom without a load cell runs
  // open loop, every beat at the recipe's speed.
  BeatRegulatorConfig beat_regulator{};
  double load_cell_max_n = 5000.0;  // a load-cell reading beyond this is a failed cell, not a beat
  motion::JerkLimits carriage{.velocity = 0.5, .acceleration = 5.0, .jerk = 100.0};  // re-arm moves
  // Row-boundary handshake: with await_row_saved, no row starts before the reporter has confirmed that
  // the row before it is on disk (note_rows_saved); a save that fails, or is not confirmed within
  // row_save_timeout_s, is the fault counters_not_saved at that safe point (beater parked, shuttle at
  // a selvedge). A recipe reloaded meanwhile is adopted by the row that follows.
  bool await_row_saved = false;
  double row_save_timeout_s = 5.0;
  // Knotting mode (handmade carpets: knot a row, pass the weft, beat): before every new row the loom
  // parks and waits for "row knotted": request_row_knotted(), which the owner also makes of a pedal press.
  bool knotting = false;
  // Knotting heads (knotting.mode = "heads"): the design as magazine slots, the knot cycle and the heads'
  // axes. Before every new row the heads tie it (RowKnotter) while the beater is parked and the shed still.
  KnottingConfig heads{};
};

// The SequencerConfig fact a refusal is about: a caller maps it to its own input (the loom file's key),
// never by reading the message. Some have no key of their own (the machine's constants).
enum class SequencerField : std::uint8_t {
  kPeriod,
  kBeatsPerPosition,
  kPicksPerRow,
  kAxes,
  kAxisMaxSpeed,  // SequencerFault::axis says which
  kDebounceTicks,
  kSensorDiscrepancy,
  kCrankParkPosition,
  kCarriageHome,
  kHelixLeftPosition,
  kEnableTimeout,
  kPickTimeoutMargin,
  kStaleTimeout,
  kDiagnosisWindow,
  kArrivalGrace,
  kRowSaveTimeout,
  kSelvedgeSensorWindow,
  kShuttleFollowTolerance,
  kKnottingHeads,
  kKnottingMode,
  kSlotColours,
  kSelectorLimits,
  kKnotterSettings,
  kBeatRegulator,  // SequencerConfig::beat_regulator (no key: the machine's constants)
};
struct SequencerFault {
  SequencerField field;
  std::size_t axis = 0;  // the axis' slot, for kAxisMaxSpeed
  std::string message;   // why, naming the config key
};

// Configure-time only. Nothing when the sequencer can run `profiles` with `cfg`, else the first refusal:
// every fixed capacity (kMaxBeatsPerRow), finite calibration offsets and time-outs whose tick counts fit
// the integer time base.
std::optional<SequencerFault> find_fault(const SequencerConfig& cfg, const motion::ProfileSet& profiles);
// Configure-time only. "" when the sequencer can run `profiles` with `cfg`, else find_fault()'s message.
std::string validate(const SequencerConfig& cfg, const motion::ProfileSet& profiles);

// Where production row `row0`'s (0-based) beat sweep starts: true at the left selvedge. Without knotting
// heads rows sweep in alternating directions, so each row starts where the last one ended. With heads every
// row starts at the right: the heads tie a row from the left selvedge, where the last sweep left the
// carriage, and the carriage then crosses once to the right to beat the row back to the left. (Alternating
// sweeps would cost a row that starts at the right two crossings before its sweep: to the knots, and back.)
constexpr bool row_sweep_starts_left(bool knotting_heads, std::uint32_t row0) noexcept {
  return !knotting_heads && row0 % 2 == 0;
}

class Sequencer {
 public:
  // Configure-time only. `profiles` must outlive the sequencer. `resume` seeds the counters (restart);
  // they are reconciled with the machine's measured state when it arms. Throws std::invalid_argument
  // when validate() refuses the configuration.
  Sequencer(const motion::ProfileSet& profiles, const SequencerConfig& cfg, Counters resume = {});
  // Configure-time only. Follows `slot`: a recipe published there is adopted at the next row boundary
  // (then the machine re-arms, so a changed width re-homes the carriage). `slot` must outlive this.
  Sequencer(motion::ProfileSlot& slot, const SequencerConfig& cfg, Counters resume = {});

  void request_start() noexcept { start_requested_ = true; }  // RT-safe
  // RT-safe. Stop: the loom comes to rest at the next point where it may stand — where a pause would hold
  // (a row's end, between the picks of a row, between two knot cycles of the heads), or at once where it
  // already stands (paused, waiting for the weaver) — and stays there in kDone. It never sets the loom
  // moving: a paused loom stays where it is, and an idle one forgets a start it has not yet taken. What is in
  // progress when it comes (a beat sweep, a pick, a knot cycle, a homing run, a re-arm move) is finished,
  // never cut short: the stop only keeps the next motion from starting. Nothing to do when done or faulted.
  void request_stop() noexcept;
  // RT-safe. Hold at the next point where a stop would stand (see request_stop), drives enabled, until
  // resumed. Never sets the loom moving; a pause while idle is nothing to hold.
  void request_pause() noexcept { pause_requested_ = true; }
  void request_resume() noexcept { pause_requested_ = false; }  // RT-safe
  // RT-safe. A pause asked for and not yet reached (the loom is still moving towards its hold point).
  bool pause_pending() const noexcept { return pause_requested_ && state_ != State::kPaused; }
  // RT-safe. A stop asked for and not yet reached.
  bool stop_pending() const noexcept { return stop_requested_ && state_ != State::kDone; }
  // RT-safe. Stop at once (the second SIGINT/SIGTERM): quick stop of every axis, valves hold, counters
  // kept, latched as the named fault stop_requested.
  void request_stop_now() noexcept { stop_now_requested_ = true; }
  // RT-safe. Acknowledge a latched fault: the drives get their fault-reset edge, the machine goes idle
  // and re-arms from measured positions on the next start. (The owner makes an ack press this request.)
  // Only after the fault: a request while no fault is latched is discarded, never kept for the next one;
  // refused (the fault stays latched) while the e-stop chain is open.
  void request_acknowledge() noexcept {
    if (state_ == State::kFault) ack_requested_ = true;
  }
  // RT-safe. The weaver has knotted the row (knotting mode): weave it. Ignored unless waiting for it.
  void request_row_knotted() noexcept { knot_requested_ = true; }
  // RT-safe. A fault found outside the sequencer (the runner's overrun policy): latched at the next step
  // with the same reaction as any other fault (quick stop, valves hold, counters kept).
  void request_safe_stop(Fault f) noexcept { external_fault_ = f; }
  // RT-safe. The reporter's latest word on the counters file: the rows it holds, and whether the most
  // recent save failed (see SequencerConfig::await_row_saved).
  void note_rows_saved(std::uint32_t rows_on_disk, bool last_save_failed) noexcept {
    rows_on_disk_ = rows_on_disk;
    last_save_failed_ = last_save_failed;
  }
  // RT-safe. The knot cycles of row `rows` (production rows before it) the counters file says were started:
  // with await_row_saved, no knot cycle starts before its start is on disk.
  void note_knots_saved(std::uint32_t rows, std::uint32_t cycles_started) noexcept {
    knots_on_disk_rows_ = rows;
    knots_on_disk_started_ = cycles_started;
  }
  // RT-safe. What the loom asks of the weaver now (kNone when nothing); requests() counts every request
  // made (a reader polling it sees each one).
  const WeaverRequest& weaver_request() const noexcept {
    static constexpr WeaverRequest kNothing{};
    return state_ == State::kKnotting ? knotter_.request() : kNothing;
  }
  std::uint32_t weaver_requests() const noexcept { return knotter_.requests(); }
  // The knotting heads as the interlocks see them (heads = 0 without).
  const KnotGuard& knot_guard() const noexcept { return interlock_ctx_.knot; }
  // The knotting heads' progress in the row (cycle, requests, magazines).
  const RowKnotter& knotter() const noexcept { return knotter_; }
  // Not RT (arming): the magazines' levels from before a restart (RowKnotter::restore_stock).
  void restore_magazines(const MagazineLevels& levels) noexcept { knotter_.restore_stock(levels); }
  // RT-safe. The weaver reloaded a slot (RowKnotter::reload): in any state, it only sets the level; an open
  // request to reload that slot is answered by it.
  bool reload_magazine(int head, int slot, std::int32_t knots) noexcept {
    return knotter_.reload(head, slot, knots);
  }
  // RT-safe. The knot cycle the heads are on (0-based) while knotting.
  int knot_cycle() const noexcept { return knotter_.cycle(); }

  // RT-safe. One tick: check faults → advance the row cycle → sample profiles → check interlocks →
  // write every field of `out`, and list what happened in events().
  void step(hal::Tick now, const hal::HalInputs& in, hal::HalOutputs& out) noexcept;
  // RT-safe. What the last step() did that is news (beats, picks, rows, faults, pauses, knots, requests,
  // button presses), in order; valid until the next step(). Readers forward it instead of comparing
  // polled state with the last tick's.
  const TickEvents& events() const noexcept { return events_; }

  State state() const noexcept { return state_; }
  // The machine's axes (slot order); the HAL's arrays are used up to axes().count.
  const hal::AxisLayout& axes() const noexcept { return cfg_.axes; }
  const Counters& counters() const noexcept { return counters_; }
  Fault first_fault() const noexcept { return first_fault_; }
  // The fault that actually stopped motion; differs from first_fault() when a symptom (stale feedback,
  // an interlock) stopped the machine and the root cause was identified within the diagnosis window.
  Fault stopped_by() const noexcept { return stopped_by_; }
  int fault_axis() const noexcept { return fault_axis_; }                // -1 when not axis-specific
  std::uint16_t fault_detail() const noexcept { return fault_detail_; }  // device code (EMCY) if any
  // The safety sensor (hal::SafetySensor) the first fault is about, or -1 (sensor_discrepancy names one).
  int fault_sensor() const noexcept { return fault_sensor_; }
  hal::Tick fault_tick() const noexcept { return fault_tick_; }
  const RowStats& last_row() const noexcept { return last_row_; }
  // The beat regulator: its bounds and target (limits()), what it has learned; and the crank's speed
  // scale in the sweep now (1 outside a sweep and open loop).
  const BeatRegulator& beat_regulator() const noexcept { return regulator_; }
  double beat_speed_scale() const noexcept { return sweeping_ ? sweep_clock_.scale() : 1.0; }
  const motion::ProfileSet& profiles() const noexcept { return *profiles_; }
  std::uint32_t recipe_changes() const noexcept { return recipe_changes_; }
  // Beater crank phase from park of the current command (rad) and the table's rocker angle there.
  double commanded_crank_phase() const noexcept;
  double commanded_rocker_angle() const noexcept;
  bool finished() const noexcept { return state_ == State::kDone || state_ == State::kFault; }
  // RT-safe. A symptom (stale feedback, an interlock trip) stopped the machine and its root cause may
  // still be reported within the diagnosis window: a run that ends now would report the symptom.
  bool diagnosis_pending(hal::Tick now) const noexcept {
    return state_ == State::kFault && is_symptom(first_fault_) && now - fault_tick_ <= diagnosis_ticks_;
  }
  // Debounced digital inputs as the sequencer last used them.
  const hal::DigitalInputs& debounced_io() const noexcept { return io_; }

 private:
  // ---- the tick, in order (see sequencer.cpp) ----
  void sense(const hal::HalInputs& raw) noexcept;
  bool check_faults(hal::Tick now, const hal::HalInputs& in) noexcept;
  bool all_quiet(hal::Tick now, const hal::HalInputs& in) const noexcept;  // check_faults' usual tick
  bool check_faults_in_order(hal::Tick now, const hal::HalInputs& in) noexcept;
  void refine_diagnosis(hal::Tick now, const hal::HalInputs& in) noexcept;
  void report_presses() noexcept;
  void run_state(hal::Tick now, const hal::HalInputs& in) noexcept;
  void play_moves(hal::Tick now) noexcept;
  void track_beat_force(const hal::HalInputs& in) noexcept;
  void signal() noexcept;
  // ---- one function per state ----
  void idle(hal::Tick now, const hal::HalInputs& in) noexcept;
  void enabling(hal::Tick now, const hal::HalInputs& in) noexcept;
  void homing(hal::Tick now, const hal::HalInputs& in) noexcept;
  void positioning(hal::Tick now, const hal::HalInputs& in) noexcept;
  void shed_test(hal::Tick now) noexcept;
  void shed(hal::Tick now) noexcept;
  void pick(hal::Tick now, const hal::HalInputs& in) noexcept;
  void beat_sweep(hal::Tick now) noexcept;
  void row_end(hal::Tick now) noexcept;
  void await_knotting(hal::Tick now) noexcept;
  void knotting(hal::Tick now, const hal::HalInputs& in) noexcept;
  bool knotters_at_rest(hal::Tick now, const hal::HalInputs& in) noexcept;  // positioning: back to TAKE first
  void paused(hal::Tick now) noexcept;
  bool hold_here(hal::Tick now) noexcept;  // at a hold point: a stop (→ done) or a pause (→ paused) takes it
  void fault(hal::Tick now) noexcept;
  // ---- transitions and helpers ----
  hal::Tick ticks(double seconds) const noexcept;
  double seconds_since(hal::Tick now, hal::Tick t0) const noexcept;
  static bool is_symptom(Fault f) noexcept;
  void latch(Fault f, hal::Tick now, int axis = -1, std::uint16_t detail = 0, int sensor = -1) noexcept;
  void enter(State s, hal::Tick now) noexcept;
  bool reconcile_at_arming(hal::Tick now, const hal::HalInputs& in) noexcept;
  void finish_arming(hal::Tick now, const hal::HalInputs& in) noexcept;  // every axis enabled and referenced
  void begin_homing(hal::Tick now,
                    const hal::HalInputs& in) noexcept;  // the next unreferenced axis, or finish
  bool shuttle_where_counters_say(hal::Tick now) noexcept;
  void begin_row(hal::Tick now) noexcept;  // a row boundary: adopt a published recipe, else shed
  void begin_shed(hal::Tick now) noexcept;
  void start_stroke(bool a_extend, bool b_extend) noexcept;
  void begin_pick(hal::Tick now, bool resumed) noexcept;
  void begin_sweep(hal::Tick now) noexcept;
  void end_row(hal::Tick now) noexcept;
  void after_row(hal::Tick now) noexcept;  // done, paused or the next row, once the boundary is passed
  void next_row(hal::Tick now) noexcept;   // a new row: first knotted by the weaver in knotting mode
  void adopt_limits() noexcept;
  void configure_knot_guard();
  Fault shed_fault(ShedVerdict v) const noexcept;
  void publish_beat(int k) noexcept;
  int beat_position(int k) const noexcept;  // carriage position (0 = left selvedge) of beat k of this sweep
  void regulate_after(int k, const BeatEvent& e) noexcept;  // the regulator's turn, once per beat
  void add_fault_event(
      EventKind kind) noexcept;  // kFaultLatched / kDiagnosisRefined with the first fault's details
  bool expect_shuttle_left() const noexcept { return counters_.picks % 2 == 0; }  // it starts at the left
  bool sweep_starts_left() const noexcept { return row_sweep_starts_left(knotter_.fitted(), counters_.rows); }
  // Where the carriage waits before the row in progress: at its sweep's start, or — a row the heads are
  // still to tie (or to finish tying) — at the left selvedge, where the heads' knotting starts.
  double row_start_m() const noexcept;
  // Every knot cycle of the row in progress is done as the counters say (tied before a restart).
  bool knots_of_row_on_record() const noexcept;
  PistonEnds ends_a() const noexcept { return {io_.piston_a_extended, io_.piston_a_retracted}; }
  PistonEnds ends_b() const noexcept { return {io_.piston_b_extended, io_.piston_b_retracted}; }

  const motion::ProfileSet* profiles_;
  motion::ProfileSlot* slot_ = nullptr;
  std::uint32_t recipe_changes_ = 0;
  SequencerConfig cfg_;
  InterlockContext interlock_ctx_;
  Counters counters_;
  State state_ = State::kIdle;
  hal::Tick state_since_ = 0;
  bool start_requested_ = false;
  bool stop_requested_ = false;
  bool pause_requested_ = false;
  bool stop_now_requested_ = false;
  bool ack_requested_ = false;
  bool acknowledged_this_tick_ = false;
  Fault external_fault_ = Fault::kNone;  // set by request_safe_stop, latched at the next step

  Fault first_fault_ = Fault::kNone;
  Fault stopped_by_ = Fault::kNone;
  hal::Tick armed_since_ = 0;
  int homing_axis_ = -1;  // the axis being homed (kHoming)  // tick the drives were first asked to enable
                          // (staleness of never-seen data)
  int fault_axis_ = -1;
  int fault_sensor_ = -1;
  std::uint16_t fault_detail_ = 0;
  hal::Tick fault_tick_ = hal::kNeverTick;

  // Commanded state: what is written each tick.
  hal::HalOutputs cmd_{};
  hal::HalOutputs prev_cmd_{};  // the last tick's axis targets and I/O, what the interlocks compare; no more
  bool enabled_outputs_ = false;  // interlocks apply once drives may move

  // Active moves: origin position + move profile started at a tick.
  struct ActiveMove {
    bool active = false;
    hal::Tick t0 = 0;
    double origin = 0.0;
    motion::JerkMove move;
  };
  ActiveMove crank_move_, carriage_move_, helix_move_;
  std::array<ActiveMove, hal::kMaxKnottingHeads> knot_park_{};  // knotting servos back to rest (positioning)
  motion::JerkLimits knot_park_limits_{
      .velocity = 2.0, .acceleration = 20.0, .jerk = 1000.0};  // slow: a gripper may hold yarn
  bool sweeping_ = false;                                      // carriage follows the cam on the crank move
  double carriage_sweep_origin_ = 0.0;
  double carriage_sweep_dir_ = 1.0;
  double crank_sweep_origin_ = 0.0;
  // The beat regulator and the sweep's warped clock (beat_regulator.hpp): the sweep move is sampled at
  // sweep_clock_.time_at(now), which is the tick time while every beat is at the recipe's speed.
  BeatRegulator regulator_;
  SweepClock sweep_clock_;

  // The pick in progress: where the carrier goes and when it entered the arrival sensor's reach.
  bool pick_to_right_ = true;
  double pick_goal_rad_ = 0.0;
  hal::Tick carrier_at_selvedge_ = hal::kNeverTick;
  double pick_start_rad_ = 0.0;
  bool pick_resumed_ = false;
  hal::Tick carrier_left_ = hal::kNeverTick;  // tick the carrier left the start sensor's reach
  double raw_arrival_at_m_ = -1.0;            // carrier distance from the goal when the raw sensor came on
  double raw_arrival_lateness_m_ = 0.0;       // how far the carrier may have gone past the edge, unseen
  // The carrier's travel per tick, so that position tests on sensor edges scale with the period and the
  // carrier's speed (a sensor edge is only seen at the next sample).
  double prev_helix_rad_ = 0.0;
  double carrier_step_m_ = 0.0;       // travel over the last tick
  double carrier_prev_step_m_ = 0.0;  // over the tick before

  // Shedding: the monitor of the change in progress; the arming test strokes (sensors proven).
  ShedMonitor shed_;
  int shed_test_step_ = 0;
  bool sensors_proven_ = false;

  // Sensors and buttons as the sequencer uses them (debounced), and plausibility state.
  Debouncer<hal::kSafetySensorCount> sensors_;          // first channels
  Debouncer<hal::kSafetySensorCount> second_channels_;  // used where wired (cfg_.second_channel)
  DualChannelSensors dual_;
  Debouncer<4> buttons_;  // start, pause, ack, row knotted
  RisingEdge start_edge_, pause_edge_, ack_edge_, knotted_edge_;
  bool knot_requested_ = false;      // "row knotted" since the loom last started waiting for it
  bool paused_in_knotting_ = false;  // the pause holds between two knot cycles: resuming goes on knotting
  bool row_knotted_ = false;         // the row about to start has been knotted
  hal::Tick knotting_ticks_ = 0;
  RowKnotter knotter_;                       // the knotting heads (fitted() when the machine has them)
  std::uint32_t knotter_requests_seen_ = 0;  // a new weaver request clears an earlier pedal press
  std::uint32_t knots_on_disk_rows_ = 0, knots_on_disk_started_ = 0;
  bool knotters_parked_ = false;        // positioning brought every knotting servo to rest
  bool knot_park_planned_ = false;      // their moves back to rest are planned
  bool crank_parking_planned_ = false;  // positioning planned the crank's move to park
  hal::DigitalInputs io_{};
  hal::DigitalInputs raw_io_{};
  int sensed_ticks_ = 0;                      // picture checks wait until the debouncer has history
  std::size_t n_axes_ = hal::kCoreAxisCount;  // cfg_.axes.count
  // This tick's inputs with debounced sensors (in_[cur_], step) and the last tick's (in_[cur_ ^ 1]): the
  // fault checks compare each axis' position, refresh tick and referenced flag with the last sample's
  // (last(i)). Alternating the two saves copying those out every tick.
  std::array<hal::HalInputs, 2> in_{};
  std::size_t cur_ = 0;
  const hal::AxisFeedback& last(std::size_t i) const noexcept { return in_[cur_ ^ 1].axes[i]; }
  std::uint32_t rows_on_disk_ = 0;  // the row-boundary handshake (note_rows_saved)
  bool last_save_failed_ = false;
  bool positions_primed_ = false;
  std::array<double, hal::kMaxAxes> max_step_{};  // the most an axis can move in one tick (m or rad)
  // The configured times the tick compares against, in ticks (ticks() of cfg_'s seconds, once).
  hal::Tick stale_ticks_ = 0, diagnosis_ticks_ = 0, arrival_grace_ticks_ = 0, enable_timeout_ticks_ = 0;
  hal::Tick row_save_timeout_ticks_ = 0;
  bool load_cell_seen_ = false;

  // Row bookkeeping.
  RowRecorder row_;
  hal::Tick phase_start_ = 0, sweep_start_ = 0;
  int row_beats_ = 0;
  int beats_published_ = 0;  // beats of this row already published as BeatEvents
  TickEvents events_;        // this tick's (step() clears it)
  RowStats last_row_{};      // the last completed row
};

}  // namespace loom::sequencer
