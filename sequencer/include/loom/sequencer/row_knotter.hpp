// The knotting heads tying one row, knot by knot: the part of the row cycle before its shed change when
// the machine description says `knotting.mode = "heads"`. Pure and RT-safe like the sequencer that drives
// it: the tick's inputs in, the heads' axes, the carriage and the grippers/cutters out; no allocation.
//
// One knot cycle ties, at once, knot j of every head's stripe (head h ties knot h·stripe + j):
//   travel   the carriage to knot j's position, each head's colour selector to the slot of its knot's colour
//            (both start while the previous knot is still being tied — as soon as its yarn is released and
//            its knots are verified; the carriage only once every gripper has left the warp);
//   check    every servo where it was sent (else knot_servo_lag / selector_jam), the carriage *measured*
//   within
//            the placement tolerance of the knot (waiting for it at most settle_s plus the feedback's allowed
//            age after its move ended, else carriage_not_at_knot), yarn left in each needed
//            slot (else the weaver is asked to reload colour X into slot s of head h), the knot position
//            empty (a yarn-present switch already on is yarn_sensor_stuck: never a knot tied twice), and —
//            when the counters are kept on disk — "cycle j started" on disk before it starts;
//   cycle    the precomputed knot cycle on every head with a knot here: gripper closes at TAKE, the linkage
//            wraps the yarn round the warp pair and pulls it to the fell, the cutter fires, the yarn-present
//            switch must be seen in the cycle's sample window;
//   verify   a head whose switch was not seen ties again once (knots_retried); a second miss asks the
//            weaver to tie knot k of row r in colour X by hand (never skipped in silence).
// After the last cycle the carriage goes back to the row's start selvedge for the shed, pick and beat.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "loom/hal/types.hpp"
#include "loom/motion/jerk_move.hpp"
#include "loom/motion/knot_cycle.hpp"
#include "loom/sequencer/faults.hpp"
#include "loom/sequencer/interlocks.hpp"
#include "loom/sequencer/knot_program.hpp"

namespace loom::sequencer {

// Knots of yarn left in each slot of each head's magazine ([head][slot]).
using MagazineLevels = std::array<std::array<std::int32_t, kMaxMagazineSlots>, hal::kMaxKnottingHeads>;

// What the loom asks of the weaver while it waits (lamp amber, buzzer): answered by the weaver's pedal or
// `ctl next` once done.
enum class WeaverAsk : std::uint8_t {
  kNone,
  kTieByHand,  // the head missed this knot twice: tie it by hand in the slot's colour
  kReload,     // the slot is out of yarn: reload it
  kCheckKnot,  // the power failed while this knot was being tied: check it, finish or tie it by hand
};
const char* weaver_ask_name(WeaverAsk a);

struct WeaverRequest {
  WeaverAsk ask = WeaverAsk::kNone;
  std::uint32_t row = 0;  // 1-based production row
  int design_row = 0;     // 0-based row of the design (bottom = 0)
  int knot = -1;          // 0-based knot in the row (left selvedge = 0); -1 for a reload
  int head = -1;          // 0-based head
  int slot = -1;          // magazine slot (its colour: the knot's, or the one to reload)
  // kReload asked before a row (the forecast): the knots the rest of the row takes from the slot and those
  // left in it; both 0 when the slot ran dry in the middle of a row (a retried knot took more yarn).
  std::int32_t knots_needed = 0, knots_left = 0;
};

// Not RT (allocates). What the request asks, in the weaver's words, naming the colour by its palette code:
// "row 3 (design row 3): tie knot 17 (head 1) by hand in colour R".
std::string describe(const WeaverRequest& r, const KnotProgram& program);

// The knotting heads' wiring and limits (SequencerConfig::knotting). `program` and `cycle` null: no heads.
struct KnottingConfig {
  const KnotProgram* program = nullptr;
  const motion::KnotCycle* cycle = nullptr;
  std::array<int, hal::kMaxKnottingHeads> knotter_axis{};   // slot of each head's knotting servo
  std::array<int, hal::kMaxKnottingHeads> selector_axis{};  // slot of each head's colour selector
  double take_position_rad = 0.0;  // knotting servo reading at the TAKE pose (commissioning)
  double selector_zero_rad = 0.0;  // selector reading with slot 0 at the TAKE point (commissioning)
  motion::JerkLimits selector{.velocity = 20.0, .acceleration = 400.0, .jerk = 20000.0};  // rad, s
  double servo_tolerance_rad = 0.05;  // a servo further than this from where it was sent is lagging
  double settle_s = 0.05;  // after a move's plan ends, how long it may take to get within tolerance
  // The same for the colour selectors; 0 = settle_s. A selector in profile position runs its drive's own
  // profile from one set-point and reports on change (at most once per TPDO inhibit time), so it may be
  // measured at its slot a little later than a cyclic one; later still, still off, it is selector_jam.
  double selector_settle_s = 0.0;
  // The carriage's measured position must be this close to the knot's before its cycle starts (m); 0: the
  // default for the program's pitch (default_placement_tolerance_m). At most half the pitch (excluded).
  double placement_tolerance_m = 0.0;
};

// Where the carriage stood when it did not arrive at a knot (the fault carriage_not_at_knot): the knot
// cycle (0-based; head h's knot h·stripe + cycle), the measured position minus the knot's (m; positive:
// right of it, as the weaver faces the loom) and the tolerance it missed.
struct CarriageMiss {
  int cycle = -1;  // -1: none
  double error_m = 0.0;
  double tolerance_m = 0.0;
};
// Not RT (allocates). "the carriage measured 20.0 mm left of the knot of knot cycle 5 (each head's knot 5
// of its stripe), tolerance 2.5 mm"; "" when `m` names no cycle.
std::string describe(const CarriageMiss& m);

// How long after its step ends the carriage may take to be measured at its knot: the servos' settle time
// plus the age a feedback value may have without being stale (`feedback_age_s`, the sequencer's
// stale_timeout_s). Later, still outside the placement tolerance, it has not arrived (carriage_not_at_knot).
inline double carriage_arrival_s(const KnottingConfig& k, double feedback_age_s) noexcept {
  return k.settle_s + feedback_age_s;
}

// Configure-time. The interlocks' picture of the heads (which axes, where the gripper is in the warp as
// knotting-servo angles), derived from `heads`' knot cycle; also what the simulated heads are told.
KnotGuard knot_guard(const KnottingConfig& heads);

// Knot counts of one row, for its RowStats.
struct RowKnots {
  int tied = 0, retried = 0, by_hand = 0;
  hal::Tick ticks = 0;         // machine knotting time (excludes waiting for the weaver)
  hal::Tick weaver_ticks = 0;  // waiting for the weaver (hand ties, reloads)
};

// The knot progress the counters keep (Counters carries these; see sequencer.hpp).
struct KnotCounters {
  std::uint32_t tied = 0, retried = 0,
                by_hand = 0;  // production totals: knots tied by the heads, knot
                              // cycles run again after a miss, knots tied by the weaver
  std::uint32_t cycles_started = 0, cycles_done = 0;  // of the row in progress (written ahead: see check)
  // The heads (bit h) whose knot of the cycle in progress (cycle `cycles_done`) is counted already — tied by
  // the head, or by the weaver — while another head of it still waits: a restart then asks the weaver to
  // check only the others, and no knot is counted twice. Zero between cycles.
  std::uint32_t cycle_heads_done = 0;
  // The row in progress's own tallies (zero between rows): after a power cut its RowKnots — what the
  // production record keeps of the row — still count the knots tied before the cut.
  std::uint32_t row_tied = 0, row_retried = 0, row_by_hand = 0;
};

class RowKnotter {
 public:
  // kHeld: asked to hold, the heads stand between two knot cycles (the next cycle's carriage step and
  // selectors arrived, nothing taken, nothing written ahead); the next step without `hold` goes on from
  // there.
  enum class Status : std::uint8_t { kRunning, kAwaitingWeaver, kDone, kFault, kHeld };

  // Configure-time. `carriage_home_m`: the carriage reading at the left selvedge; `carriage` its limits.
  // `guard`: where a knotting servo holds its gripper in the warp (the interlocks' own test): no carriage
  // move starts while a measured gripper is there. Must outlive the knotter. `feedback_age_s`: how old a
  // feedback value may be without being stale (the sequencer's stale_timeout_s): a carriage whose
  // measured position is not at its knot settle_s + feedback_age_s after its move ended has not arrived.
  void configure(const KnottingConfig& k, const KnotGuard* guard, double period_s, double carriage_home_m,
                 const motion::JerkLimits& carriage, double feedback_age_s = 0.0);
  bool fitted() const noexcept { return k_.program != nullptr && k_.cycle != nullptr; }

  // RT-safe. Start tying production row `row0` (0-based, = counters.rows) from the counters' progress;
  // `return_to_m` is where the carriage goes when the row is knotted (its start selvedge, from home).
  // `cmd` holds the current targets (every move starts from them). A cycle that was started but not
  // finished (the power failed in it) is asked of the weaver first.
  void begin(std::uint32_t row0, const KnotCounters& progress, double return_to_m, hal::Tick now,
             const hal::HalOutputs& cmd) noexcept;
  // What the sequencer tells the heads each tick.
  struct StepInputs {
    bool weaver_done = false;           // the weaver answered the request (only read while one is open)
    bool hold = false;                  // a stop or a pause: stand at the next point between two knot cycles
    bool await_disk = false;            // no cycle starts before its start is on disk ...
    std::uint32_t on_disk_started = 0;  // ... as the counters file holds the row's cycles-started count
    hal::Tick disk_timeout_ticks = 0;   // ... within this many ticks, else counters_not_saved (0: no limit)
  };
  // RT-safe. One tick.
  Status step(hal::Tick now, const hal::HalInputs& in, hal::HalOutputs& cmd, KnotCounters& counters,
              const StepInputs& s) noexcept;

  Fault fault() const noexcept { return fault_; }
  int fault_axis() const noexcept { return fault_axis_; }
  // RT-safe. The knot the carriage did not arrive at (cycle -1 unless the fault is carriage_not_at_knot).
  const CarriageMiss& carriage_miss() const noexcept { return miss_; }
  // The knot-placement tolerance in use (m).
  double placement_tolerance_m() const noexcept { return tolerance_m_; }
  const WeaverRequest& request() const noexcept { return request_; }
  std::uint32_t requests() const noexcept { return requests_; }  // counts requests made (never reset)
  // RT-safe. The last step() changed `counters` (a cycle started or done, a knot tied, retried or tied by
  // hand): the sequencer's kKnotProgress.
  bool counters_moved() const noexcept { return counters_moved_; }
  const RowKnots& row() const noexcept { return row_; }
  int cycle() const noexcept { return j_; }  // the knot cycle in progress (0-based)
  // RT-safe. Yarn left in slot `slot` of head `head`'s magazine, in knots, as the loom counts it (-1 when
  // unknown: before the first row or out of range).
  // Not RT (arming, before the first row): the magazines' levels kept from before a restart (knots per
  // slot, [head][slot]; a negative level is read as empty) instead of full magazines at the first row.
  void restore_stock(const MagazineLevels& levels) noexcept;
  // RT-safe. The weaver put yarn in slot `slot` of head `head` (both 0-based): it now holds `knots` knots
  // (negative: full; more than a full slot is read as full). It answers an open request to reload that
  // slot (the heads go on). False, and nothing changed, when there is no such head or slot.
  bool reload(int head, int slot, std::int32_t knots) noexcept;
  std::int32_t stock(int head, int slot) const noexcept {
    if (!stock_known_ || head < 0 || head >= heads_ || slot < 0 || slot >= kMaxMagazineSlots) return -1;
    return stock_[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)];
  }

  // RT-safe. The servo angle of a knotting servo at rest (TAKE) nearest behind `position`: where a
  // servo stopped inside a cycle goes back to (the way it came).
  double rest_behind(double position) const noexcept;

 private:
  enum class Phase : std::uint8_t { kTravel, kCheck, kCycle, kWeaver, kReturn, kDone };
  struct Move {
    bool active = false;
    bool started = false;  // has moved (the carriage's waits, at its origin, until no gripper is in the warp)
    hal::Tick t0 = 0;
    double origin = 0.0;
    motion::JerkMove move;
  };
  void plan_travel(int j, hal::Tick now,
                   const hal::HalOutputs& cmd) noexcept;  // carriage and selectors to cycle j
  void plan_selectors(int j, hal::Tick now, const hal::HalOutputs& cmd) noexcept;
  void plan_carriage(int j, hal::Tick now, const hal::HalOutputs& cmd) noexcept;
  void enter_cycle(int j, hal::Tick now,
                   const hal::HalOutputs& cmd) noexcept;  // cycle j: travel (if not begun), check
  void start_cycle(hal::Tick now) noexcept;
  void finish_cycle(hal::Tick now, const hal::HalOutputs& cmd, KnotCounters& counters) noexcept;
  void cycle_done(hal::Tick now, const hal::HalOutputs& cmd, KnotCounters& counters) noexcept;
  void ask(WeaverAsk a, int head, int knot, int slot, hal::Tick now) noexcept;
  Status check(hal::Tick now, const hal::HalInputs& in, const hal::HalOutputs& cmd, KnotCounters& counters,
               const StepInputs& s) noexcept;
  void run_cycle(hal::Tick now, const hal::HalInputs& in, hal::HalOutputs& cmd,
                 KnotCounters& counters) noexcept;
  Status weaver(hal::Tick now, const hal::HalOutputs& cmd, KnotCounters& counters, bool weaver_done) noexcept;
  bool ask_reload_for_row(hal::Tick now) noexcept;  // the forecast before the row's knots: true when it asked
  bool play(Move& m, hal::Tick now,
            double& target) const noexcept;  // true when it moved the target this tick
  bool fail(Fault f, int axis) noexcept;
  double seconds(hal::Tick dt) const noexcept { return static_cast<double>(dt) * period_s_; }
  double selector_goal(int slot, double from) const noexcept;

  KnottingConfig k_{};
  const KnotGuard* guard_ = nullptr;
  double period_s_ = 0.002, carriage_home_m_ = 0.0;
  motion::JerkLimits carriage_{};
  double return_to_m_ = 0.0;
  std::uint32_t row0_ = 0;
  int heads_ = 0, stripe_ = 0;
  Phase phase_ = Phase::kDone;
  hal::Tick phase_since_ = 0, row_since_ = 0, weaver_since_ = 0;
  hal::Tick disk_wait_since_ =
      hal::kNeverTick;                   // the write-ahead of the cycle in check is waiting for the disk
  int j_ = 0;                            // knot cycle in progress
  int attempt_ = 0;                      // 0 first try, 1 the retry
  bool interrupted_ = false;             // cycle j_ was started before a power cut: ask the weaver first
  std::uint32_t heads_done_at_cut_ = 0;  // ... except of these heads, whose knots the counters hold
  int ask_head_ = 0;                     // next head to consider for a request in kWeaver
  bool forecast_due_ = false;     // the row's yarn is not checked yet: no cycle of this begin() has started
  bool reload_answered_ = false;  // reload() filled the slot the open kReload request names
  WeaverAsk hand_ask_ = WeaverAsk::kTieByHand;  // what kWeaver asks for the heads in missed_
  Move carriage_move_{};
  std::array<Move, hal::kMaxKnottingHeads> selector_move_{};
  std::array<double, hal::kMaxKnottingHeads> knotter_origin_{};
  std::array<int, hal::kMaxKnottingHeads>
      slot_{};  // slot each head's selector is at (or going to), -1 unknown
  std::array<bool, hal::kMaxKnottingHeads> active_{};  // head ties in this cycle
  std::array<bool, hal::kMaxKnottingHeads> seen_{};    // its yarn-present switch was seen in the window
  std::array<bool, hal::kMaxKnottingHeads> missed_{};  // needs the weaver's hand after the second miss
  std::array<std::array<std::int32_t, kMaxMagazineSlots>, hal::kMaxKnottingHeads>
      stock_{};  // knots left per slot
  bool stock_known_ = false;
  bool next_selectors_ = false;  // the next cycle's selector moves began inside this one
  bool next_carriage_ = false;   // and its carriage step
  hal::Tick cycle_t0_ = 0;
  Fault fault_ = Fault::kNone;
  int fault_axis_ = -1;
  CarriageMiss miss_{};
  double tolerance_m_ = 0.0;     // knot placement (the config's, or the default for the pitch)
  hal::Tick arrival_ticks_ = 0;  // how long after its move the carriage may take to be measured there
  WeaverRequest request_{};
  std::uint32_t requests_ = 0;
  bool counters_moved_ = false;  // by the last step()
  RowKnots row_{};
};

}  // namespace loom::sequencer
