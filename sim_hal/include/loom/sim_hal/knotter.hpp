// The knotting heads as the simulator sees them (scene effect "knotter"): each head's magazine of yarn,
// its gripper taking yarn at the TAKE pose from the slot its selector stands at, the knot tied where the
// cutter fires with the gripper in the warp (or missed, with the scene's probability), the yarn-present
// switch seeing a knot at the head's knot position, and a simulated weaver who does what the loom asks
// (ties a knot by hand, reloads a slot) after a while and then presses the pedal. It records the carpet it
// actually knotted, one cell per knot, so a run can be compared with its design knot for knot. The carpet is
// as long as the carpet being woven: its room is sized at configure time (never in the tick) from the rows
// the run will weave, and a knot beyond that room is counted (rows_beyond()), never silently dropped. Built
// only when a scene names the effect: a scene without it pays nothing per tick.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "loom/hal/types.hpp"
#include "loom/sim_hal/random.hpp"

namespace loom::sim_hal {

// The heads' machine facts (from the loom config; heads = 0 when the loom has none).
struct SimKnotting {
  int heads = 0;
  int knots_per_row = 0;
  int stripe = 0;          // knots per head's stripe
  int slots = 0;           // magazine slots per head
  int knots_per_slot = 0;  // yarn in a full slot
  double pitch_m = 0.0;
  double carriage_home_m = 0.0;
  std::array<std::size_t, hal::kMaxKnottingHeads> knotter_axis{};
  std::array<std::size_t, hal::kMaxKnottingHeads> selector_axis{};
  double take_position_rad = 0.0;
  double selector_zero_rad = 0.0;
  // Knotting-servo angles (relative to TAKE; wrapped to [0, 2π) when full_turn) with the gripper in the warp.
  double in_warp_from_rad = 0.0, in_warp_to_rad = 0.0;
  bool full_turn = true;
  // The carpet's length, for the room its record needs: the production row the run stops after (0: no end
  // given) and the design's rows (a pass of the design when the run has no end).
  std::uint32_t last_row = 0;
  int design_rows = 0;
};

// The scene's parameters of the effect.
struct Knotter {
  double miss_probability = 0.0;  // a knot slips off and is not tied (per cycle)
  double weaver_s = 20.0;         // how long the weaver takes to do what the loom asks
  // Rows of carpet recorded. 0 (the default): as many as the run weaves (from the production row the run
  // stops after, or without one a pass of the design but no fewer than kUnboundedRows). N: exactly N (a
  // test's deliberately short carpet); a knot beyond them is counted as beyond the record.
  int carpet_rows = 0;
  static constexpr int kUnboundedRows = 64;
};

// One knot of the carpet as tied.
struct KnotCell {
  std::int8_t slot = -1;  // magazine slot whose yarn it is (-1: no knot)
  std::uint8_t ties = 0;  // knots tied here (more than one is a defect; counted up to 3)
  bool by_hand = false;   // tied by the weaver
};

// The knotter's state as it persists across a power cut (in the sim-state file, or owned): the carpet's
// first production row, the row being knotted, the yarn in every slot. Plain data; the carpet's cells, one
// byte per knot (packed KnotCell), follow it in the same memory (knot_cells()).
struct PersistedCarpet {
  static constexpr std::uint64_t kMagic = 0x4b4e4f5453494d32ull;  // "KNOTSIM2"
  static constexpr int kMaxSlots =
      16;  // magazine slots a head's stock holds (a cell packs slot + 1 in 5 bits)
  std::uint64_t magic = 0;
  std::uint32_t first_row = 0;     // production row (counters) of carpet row 0
  std::int32_t knots_per_row = 0;  // the carpet's width (a different loom starts a new carpet)
  std::int32_t row = 0;            // the row being knotted
  std::int32_t row_has_knots = 0;
  std::uint32_t knots_beyond = 0;  // knots tied in rows beyond the record's room (a record too short)
  std::uint32_t reserved = 0;
  std::array<std::array<std::int32_t, kMaxSlots>, hal::kMaxKnottingHeads> stock{};
};
static_assert(sizeof(PersistedCarpet) % 8 == 0, "the cells follow the header 8-byte aligned");

// The carpet's cells (one byte per knot) right after its header.
inline std::uint8_t* knot_cells(PersistedCarpet& c) noexcept {
  return reinterpret_cast<std::uint8_t*>(&c + 1);
}
inline const std::uint8_t* knot_cells(const PersistedCarpet& c) noexcept {
  return reinterpret_cast<const std::uint8_t*>(&c + 1);
}

// Where a carpet is kept: the sim-state file's carpet area (it survives the process), or memory owned by the
// knotter. Configure-time only: reserve() grows the room (keeping what is there), never in the tick.
class CarpetKeeper {
 public:
  // The carpet header with room for at least `cells` knots after it; throws std::runtime_error (naming where
  // and how much) when it cannot have that room.
  virtual PersistedCarpet& reserve(std::size_t cells) = 0;
  // Knots of room now after the header (0: none yet).
  virtual std::size_t room() const noexcept = 0;

 protected:
  CarpetKeeper() = default;
  CarpetKeeper(const CarpetKeeper&) = default;
  CarpetKeeper& operator=(const CarpetKeeper&) = default;
  ~CarpetKeeper() = default;
};

// What the weaver is asked (the loom's request, as the panel shows it).
struct WeaverTask {
  enum class Kind : std::uint8_t { kTieByHand, kCheckKnot, kReload };
  Kind kind = Kind::kTieByHand;
  int head = 0;
  int knot = 0;  // 0-based knot of the row being knotted (tie / check)
  int slot = 0;  // its colour's slot (tie, check) or the slot to reload
};

class SimKnotter {
 public:
  // Configure-time (allocates the carpet: a fresh one at production row 0).
  SimKnotter(const SimKnotting& m, const Knotter& k, double period_s);
  ~SimKnotter();
  SimKnotter(const SimKnotter&) = delete;
  SimKnotter& operator=(const SimKnotter&) = delete;
  // Configure-time. Keep the carpet and the magazines in `keeper` (a sim-state file's): a carpet found there
  // for this loom's width is adopted (the run after a power cut carries on knotting it), otherwise a fresh
  // one is started there at production row `counter_rows`; either way its room grows to the run's rows.
  // `carpet_began`: the production row the carpet on the loom began at (a carpet job's first row): a kept
  // carpet begun before it is another carpet, cut off the loom, and a fresh one starts.
  // Throws std::runtime_error when the keeper cannot have the room.
  void persist_in(CarpetKeeper& keeper, std::uint32_t counter_rows,
                  std::optional<std::uint32_t> carpet_began = std::nullopt);
  // Configure-time, the knotter's own carpet (no keeper): a fresh carpet at production row `counter_rows`.
  void start_at_row(std::uint32_t counter_rows);
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
  // RT-safe. The weaver (the operator's `reload`, not a task of the simulated weaver's) put yarn in a slot:
  // `knots` knots (negative, or more than a slot holds: full). Out of range: ignored.
  void reload(int head, int slot, std::int32_t knots) noexcept;

  // The carpet as knotted: rows() complete or in progress (the last may be partial), knots_per_row() each;
  // of them the first capacity_rows() are recorded (cell() of a later row is no knot) and knots_beyond()
  // knots were tied after the record's room ran out (0 unless the scene's carpet_rows was too short).
  int rows() const noexcept { return st_->row + (st_->row_has_knots ? 1 : 0); }
  int knots_per_row() const noexcept { return m_.knots_per_row; }
  KnotCell cell(int row, int knot) const noexcept;
  int capacity_rows() const noexcept { return capacity_rows_; }
  std::uint32_t knots_beyond() const noexcept { return st_->knots_beyond; }
  std::uint32_t tasks_done() const noexcept { return tasks_done_; }
  // Ground truth for checkers: is head h's gripper (its servo at `knotter` rad) in the warp, is it closed.
  bool gripper_in_warp(int head, double knotter) const noexcept {
    return head >= 0 && head < m_.heads && in_warp(knotter);
  }
  bool gripper_closed(int head) const noexcept {
    return head >= 0 && head < m_.heads && gripper_[static_cast<std::size_t>(head)];
  }

 private:
  class OwnCarpet;
  int knot_under(int head, double carriage) const noexcept;  // -1 when between knots
  bool in_warp(double knotter) const noexcept;
  // The cell of knot `knot` in the row being knotted (the scratch row once beyond the record's room).
  std::uint8_t& current(int knot) noexcept;
  std::uint8_t current_cell(int knot) const noexcept;
  void tie(int knot, int slot, bool by_hand) noexcept;
  int rows_needed(std::uint32_t first_row, int rows_knotted) const noexcept;
  void keep_in(CarpetKeeper& keeper, std::uint32_t counter_rows, bool adopt,
               std::optional<std::uint32_t> carpet_began = std::nullopt);

  SimKnotting m_;
  Knotter k_;
  double period_s_;
  std::unique_ptr<OwnCarpet> own_;  // the carpet's memory when no sim-state file keeps it
  PersistedCarpet* st_ = nullptr;   // where it is kept
  std::uint8_t* cells_ = nullptr;   // its cells (knot_cells(*st_))
  int capacity_rows_ = 0;           // rows of carpet recorded (the room, in rows)
  std::vector<std::uint8_t>
      beyond_;  // one scratch row for knots beyond the room (so the heads still see them)
  std::array<int, hal::kMaxKnottingHeads> holding_{};  // slot of the yarn in the gripper, -1 none
  std::array<bool, hal::kMaxKnottingHeads> gripper_{}, cutter_{};
  // The weaver: one task at a time.
  bool task_pending_ = false;
  WeaverTask task_{};
  std::int64_t task_left_ = 0;  // ticks until done
  int pedal_left_ = 0;          // ticks the pedal stays pressed
  std::uint32_t tasks_done_ = 0;
};

}  // namespace loom::sim_hal
