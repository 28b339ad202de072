// The design as magazine slots (see knot_program.hpp).
#include "loom/sequencer/knot_program.hpp"

#include <stdexcept>

namespace loom::sequencer {

KnotProgram KnotProgram::build(const KnottingSpec& spec, double width_m, int design_width, int design_height,
                               std::span<const std::uint16_t> knots_bottom_up,
                               std::span<const std::string> palette_codes, std::uint64_t design_rows_done,
                               std::uint32_t counter_rows_at_start) {
  if (const std::string why = validate(spec, width_m); !why.empty()) throw std::invalid_argument(why);
  if (design_width < 1 || design_height < 1 ||
      knots_bottom_up.size() !=
          static_cast<std::size_t>(design_width) * static_cast<std::size_t>(design_height)) {
    throw std::invalid_argument("the design holds no knots");
  }
  KnotProgram p;
  p.heads_ = spec.heads;
  p.knots_ = sequencer::knots_per_row(spec, width_m);
  p.stripe_ = knots_per_stripe(spec);
  p.slots_ = static_cast<int>(spec.slot_colours.size());
  p.pitch_m_ = knot_pitch_m(spec);
  p.knots_per_slot_ = spec.knots_per_slot;
  p.design_rows_ = design_height;
  p.design_rows_done_ = design_rows_done;
  p.counter_rows_at_start_ = counter_rows_at_start;
  p.slot_colours_ = spec.slot_colours;
  p.slot_.reserve(knots_bottom_up.size());
  std::array<int, kMaxKnottingHeads> selector{};
  selector.fill(-1);
  const auto w = static_cast<std::size_t>(design_width);
  for (int r = 0; r < design_height; ++r) {
    const auto row = knots_bottom_up.subspan(static_cast<std::size_t>(r) * w, w);
    try {
      (void)plan_row(spec, width_m, row, palette_codes, selector);  // the width and every colour's slot
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("design row " + std::to_string(r + 1) + ": " + e.what());
    }
    for (const std::uint16_t colour : row)
      p.slot_.push_back(static_cast<std::uint8_t>(slot_of(spec, palette_codes[colour])));
  }
  return p;
}

int KnotProgram::design_row(std::uint32_t counter_row) const noexcept {
  if (design_rows_ == 0) return 0;
  // Rows before the start map back too (a carpet compared from its first row after restarts).
  const auto h = static_cast<std::int64_t>(design_rows_);
  const std::int64_t d =
      static_cast<std::int64_t>(design_rows_done_ % static_cast<std::uint64_t>(h)) +
      (static_cast<std::int64_t>(counter_row) - static_cast<std::int64_t>(counter_rows_at_start_)) % h;
  return static_cast<int>(((d % h) + h) % h);
}

int KnotProgram::slot(std::uint32_t counter_row, int k) const noexcept {
  if (design_rows_ == 0 || k < 0 || k >= knots_) return -1;
  const std::size_t at =
      static_cast<std::size_t>(design_row(counter_row)) * static_cast<std::size_t>(knots_) +
      static_cast<std::size_t>(k);
  return slot_[at];
}

}  // namespace loom::sequencer
