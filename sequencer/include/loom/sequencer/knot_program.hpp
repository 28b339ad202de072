// The design as the knotting heads tie it: for every design row, the magazine slot of every knot, built
// once at configure time and only read by the tick (no allocation after construction). It also maps a
// production row (the counters) to the design row it ties, in the design's own orientation (design row 0
// is the bottom of the picture, the first row woven), repeating the design when the carpet is longer.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "loom/sequencer/knot_plan.hpp"

namespace loom::sequencer {

class KnotProgram {
 public:
  KnotProgram() = default;  // empty: the loom has no knotting heads (or no design)

  // Configure-time. `knots_bottom_up` is the design row-major, bottom row first, `design_width` knots per
  // row; `palette_codes` names each palette index. `design_rows_done` design rows were woven by production
  // row `counter_rows_at_start`. Throws std::invalid_argument (naming the colour and knot, or the width)
  // when the design does not fit the loom or its magazines (plan_row's checks), or validate(spec) refuses.
  static KnotProgram build(const KnottingSpec& spec, double width_m, int design_width, int design_height,
                           std::span<const std::uint16_t> knots_bottom_up,
                           std::span<const std::string> palette_codes, std::uint64_t design_rows_done,
                           std::uint32_t counter_rows_at_start);

  bool empty() const noexcept { return design_rows_ == 0; }
  int heads() const noexcept { return heads_; }
  int knots_per_row() const noexcept { return knots_; }
  int stripe() const noexcept { return stripe_; }  // knots per head's stripe (cycles per row)
  int slots() const noexcept { return slots_; }    // magazine slots per head
  double pitch_m() const noexcept { return pitch_m_; }
  int knots_per_slot() const noexcept { return knots_per_slot_; }
  int design_rows() const noexcept { return design_rows_; }

  // RT-safe. The design row production row `counter_row` (0-based: counters.rows before the row) ties (rows
  // before the one the program started at map back the same way).
  int design_row(std::uint32_t counter_row) const noexcept;
  // RT-safe. Knot `k` (0 = left selvedge) of production row `counter_row`: its magazine slot.
  int slot(std::uint32_t counter_row, int k) const noexcept;
  // RT-safe. The knot head `h` ties in cycle `j`, or -1 when its stripe has no knot there (a short last
  // stripe).
  int knot_of(int h, int j) const noexcept {
    const int k = h * stripe_ + j;
    return j >= 0 && j < stripe_ && k < knots_ ? k : -1;
  }
  // RT-safe. Carriage position (from the left selvedge) at which head 0 sits over knot `j` (and head h
  // over knot h·stripe + j): the middle of the knot's pitch.
  double carriage_at(int j) const noexcept { return (j + 0.5) * pitch_m_; }
  // Configure-time (messages). The palette code in slot `s`.
  const std::string& slot_colour(int s) const { return slot_colours_[static_cast<std::size_t>(s)]; }

 private:
  int heads_ = 0, knots_ = 0, stripe_ = 0, slots_ = 0, knots_per_slot_ = 0, design_rows_ = 0;
  double pitch_m_ = 0.0;
  std::uint64_t design_rows_done_ = 0;
  std::uint32_t counter_rows_at_start_ = 0;
  std::vector<std::uint8_t> slot_;  // [design row · knots + k]
  std::vector<std::string> slot_colours_;
};

}  // namespace loom::sequencer
