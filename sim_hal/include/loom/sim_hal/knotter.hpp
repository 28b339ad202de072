// The knotting heads as the simulator sees them (scene effect "knotter"): each head's magazine of yarn,
// its gripper taking yarn at the TAKE pose from the slot its selector stands at, the knot tied where the
// cutter fires with the gripper in the warp (or missed, with the scene's probability), the yarn-present
// switch seeing a knot at the head's knot position, and a simulated weaver who does what the loom asks
// (ties a knot by hand, reloads a slot) after a while and then presses the pedal. It records the carpet it
// actually knotted, one cell per knot, so a run can be compared with its design knot for knot.
// Built only when a scene names the effect: a scene without it pays nothing per tick.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "loom/hal/types.hpp"
#include "loom/sim_hal/random.hpp"

namespace loom::sim_hal {

// The heads' machine facts (from the loom config; heads = 0 when the loom has none).
struct SimKnotting {
  int heads = 0;
  int knots_per_row = 0;
  int stripe = 0;            // knots per head's stripe
  int slots = 0;             // magazine slots per head
  int knots_per_slot = 0;    // yarn in a full slot
  double pitch_m = 0.0;
  double carriage_home_m = 0.0;
  std::array<std::size_t, hal::kMaxKnottingHeads> knotter_axis{};
  std::array<std::size_t, hal::kMaxKnottingHeads> selector_axis{};
  double take_position_rad = 0.0;
  double selector_zero_rad = 0.0;
  // Knotting-servo angles (relative to TAKE; wrapped to [0, 2π) when full_turn) with the gripper in the warp.
  double in_warp_from_rad = 0.0, in_warp_to_rad = 0.0;
  bool full_turn = true;
};

// The scene's parameters of the effect.
struct Knotter {
  double miss_probability = 0.0;  // a knot slips off and is not tied (per cycle)
  double weaver_s = 20.0;         // how long the weaver takes to do what the loom asks
  int carpet_rows = 64;           // rows of carpet recorded (allocated once)
};

// One knot of the carpet as tied.
struct KnotCell {
  std::int8_t slot = -1;    // magazine slot whose yarn it is (-1: no knot)
  std::uint8_t ties = 0;    // knots tied here (more than one is a defect)
  bool by_hand = false;     // tied by the weaver
};

// The knotter's whole state as it persists across a power cut (in the sim-state file, or owned): the carpet
// with its first production row, the row being knotted, and the yarn in every slot. Plain data.
struct PersistedCarpet {
  static constexpr std::size_t kCells = 1u << 16;  // knots recorded: 64 rows of 1024, 182 rows of 360
  static constexpr std::uint64_t kMagic = 0x4b4e4f5453494d31ull;  // "KNOTSIM1"
  std::uint64_t magic = 0;
  std::uint32_t first_row = 0;       // production row (counters) of carpet row 0
  std::int32_t knots_per_row = 0;    // the carpet's width (a different loom starts a new carpet)
  std::int32_t row = 0;              // the row being knotted
  std::int32_t row_has_knots = 0;
  std::array<std::array<std::int32_t, 16>, hal::kMaxKnottingHeads> stock{};
  std::array<KnotCell, kCells> cells{};
};

// What the weaver is asked (the loom's request, as the panel shows it).
struct WeaverTask {
  enum class Kind : std::uint8_t { kTieByHand, kCheckKnot, kReload };
  Kind kind = Kind::kTieByHand;
  int head = 0;
  int knot = 0;   // 0-based knot of the row being knotted (tie / check)
  int slot = 0;   // its colour's slot (tie, check) or the slot to reload
};

class SimKnotter {
 public:
  // Configure-time (allocates the carpet: a fresh one at production row 0).
  SimKnotter(const SimKnotting& m, const Knotter& k, double period_s);
  // Configure-time. Keep the carpet and the magazines in `persisted` (a sim-state file's): a carpet found
  // there for this loom's width is adopted (the run after a power cut carries on knotting it), otherwise a
  // fresh one is started there at production row `counter_rows`.
  void persist_in(PersistedCarpet& persisted, std::uint32_t counter_rows);
  // Configure-time, fresh carpets only: the production row carpet row 0 is.
  void start_at_row(std::uint32_t counter_rows) noexcept {
    if (st_ == own_.get()) st_->first_row = counter_rows;
  }
  std::uint32_t first_row() const noexcept { return st_->first_row; }

  // RT-safe. One tick of outputs with the axes' true positions (carriage and every head's servos).
  void on_outputs(const hal::DigitalOutputs& out, const std::array<double, hal::kMaxAxes>& position,
                  SimRandom& rng) noexcept;
  // RT-safe. The heads' yarn-present switches and the weaver's pedal.
  void inputs(const std::array<double, hal::kMaxAxes>& position, hal::DigitalInputs& io) noexcept;
  // RT-safe. A weft was inserted: the row of knots tied so far is locked in; the next knots start a new row.
  void on_weft() noexcept;
  // RT-safe. The loom asks the weaver.
  void ask(const WeaverTask& t) noexcept;
  // RT-safe. Scene faults: a slot runs out of yarn; a selector jams (its axis stops following: SimWorld).
  void yarn_out(int head, int slot) noexcept;

  // The carpet as knotted: rows() complete or in progress (the last may be partial), knots_per_row() each.
  int rows() const noexcept { return st_->row + (st_->row_has_knots ? 1 : 0); }
  int knots_per_row() const noexcept { return m_.knots_per_row; }
  const KnotCell& cell(int row, int knot) const noexcept;
  int overflow_knots() const noexcept { return overflow_; }  // knots beyond the recorded rows
  std::uint32_t tasks_done() const noexcept { return tasks_done_; }
  // Ground truth for checkers: is head h's gripper (its servo at `knotter` rad) in the warp, is it closed.
  bool gripper_in_warp(int head, double knotter) const noexcept { return head >= 0 && head < m_.heads && in_warp(knotter); }
  bool gripper_closed(int head) const noexcept { return head >= 0 && head < m_.heads && gripper_[static_cast<std::size_t>(head)]; }

 private:
  int knot_under(int head, double carriage) const noexcept;  // -1 when between knots
  bool in_warp(double knotter) const noexcept;
  void tie(int row, int knot, int slot, bool by_hand) noexcept;

  SimKnotting m_;
  Knotter k_;
  double period_s_;
  std::unique_ptr<PersistedCarpet> own_;  // the carpet when no sim-state file keeps it
  PersistedCarpet* st_;                   // where it is kept
  int capacity_rows_ = 0;                 // rows of carpet recorded (the scene's carpet_rows, bounded by kCells)
  int overflow_ = 0;
  std::array<int, hal::kMaxKnottingHeads> holding_{};  // slot of the yarn in the gripper, -1 none
  std::array<bool, hal::kMaxKnottingHeads> gripper_{}, cutter_{};
  // The weaver: one task at a time.
  bool task_pending_ = false;
  WeaverTask task_{};
  std::int64_t task_left_ = 0;   // ticks until done
  int pedal_left_ = 0;           // ticks the pedal stays pressed
  std::uint32_t tasks_done_ = 0;
};

}  // namespace loom::sim_hal
