// The simulated knotting heads (see knotter.hpp).
#include "loom/sim_hal/knotter.hpp"

#include <algorithm>
#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::sim_hal {
namespace {
constexpr double kPoseTolerance = 0.05;  // rad: a servo this close to a pose is at it
constexpr int kPedalTicks = 10;          // the weaver's pedal press (longer than any debounce)
}  // namespace

namespace {
void fresh(PersistedCarpet& c, const SimKnotting& m, std::uint32_t first_row) {
  c.magic = PersistedCarpet::kMagic;
  c.first_row = first_row;
  c.knots_per_row = m.knots_per_row;
  c.row = 0;
  c.row_has_knots = 0;
  for (auto& head : c.stock) head.fill(m.knots_per_slot);
  c.cells.fill(KnotCell{});
}
}  // namespace

SimKnotter::SimKnotter(const SimKnotting& m, const Knotter& k, double period_s)
    : m_(m), k_(k), period_s_(period_s), own_(std::make_unique<PersistedCarpet>()), st_(own_.get()) {
  capacity_rows_ = std::min(std::max(1, k.carpet_rows),
                            static_cast<int>(PersistedCarpet::kCells / static_cast<std::size_t>(std::max(1, m.knots_per_row))));
  fresh(*st_, m_, 0);
  holding_.fill(-1);
}

void SimKnotter::persist_in(PersistedCarpet& persisted, std::uint32_t counter_rows) {
  const bool ours = persisted.magic == PersistedCarpet::kMagic && persisted.knots_per_row == m_.knots_per_row &&
                    persisted.row >= 0 && persisted.row <= capacity_rows_;
  if (!ours) fresh(persisted, m_, counter_rows);
  st_ = &persisted;
  own_.reset();
}

const KnotCell& SimKnotter::cell(int row, int knot) const noexcept {
  static const KnotCell kNone{};
  if (row < 0 || row >= capacity_rows_ || knot < 0 || knot >= m_.knots_per_row) return kNone;
  return st_->cells[static_cast<std::size_t>(row) * static_cast<std::size_t>(m_.knots_per_row) + static_cast<std::size_t>(knot)];
}

int SimKnotter::knot_under(int head, double carriage) const noexcept {
  // Head h rides h·stripe pitches right of head 0; head 0 is over knot j when the carriage stands at the
  // middle of its pitch (within a quarter pitch).
  const double u = (carriage - m_.carriage_home_m) / m_.pitch_m - 0.5;
  const double j = std::round(u);
  if (!(std::abs(u - j) <= 0.25) || j < 0.0 || j >= m_.stripe) return -1;
  const int k = head * m_.stripe + static_cast<int>(j);
  return k < m_.knots_per_row ? k : -1;
}

bool SimKnotter::in_warp(double knotter) const noexcept {
  double rel = knotter - m_.take_position_rad;
  if (m_.full_turn) rel = motion::wrap_two_pi(rel);
  return rel > m_.in_warp_from_rad && rel < m_.in_warp_to_rad;
}

void SimKnotter::tie(int row, int knot, int slot, bool by_hand) noexcept {
  if (row >= capacity_rows_) {
    ++overflow_;
    return;
  }
  KnotCell& c = st_->cells[static_cast<std::size_t>(row) * static_cast<std::size_t>(m_.knots_per_row) + static_cast<std::size_t>(knot)];
  if (c.ties < 255) ++c.ties;
  c.slot = static_cast<std::int8_t>(slot);
  c.by_hand = by_hand;
  st_->row_has_knots = 1;
}

void SimKnotter::on_outputs(const hal::DigitalOutputs& out, const std::array<double, hal::kMaxAxes>& position,
                            SimRandom& rng) noexcept {
  const double carriage = position[hal::index(hal::CoreAxis::kCarriage)];
  for (int h = 0; h < m_.heads; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    const double knotter = position[m_.knotter_axis[hh]];
    // The gripper closing at TAKE takes yarn from the slot the selector stands at (none if it stands
    // between slots or the slot is empty).
    if (out.gripper_close[hh] && !gripper_[hh]) {
      double rel = knotter - m_.take_position_rad;
      if (m_.full_turn) rel = motion::wrap_pi(rel);
      const double pitch = motion::kTwoPi / m_.slots;
      const double u = motion::wrap_two_pi(position[m_.selector_axis[hh]] - m_.selector_zero_rad) / pitch;
      const int s = static_cast<int>(std::lround(u)) % m_.slots;
      const bool at_slot = std::abs(u - std::round(u)) * pitch <= kPoseTolerance;
      holding_[hh] = -1;
      if (std::abs(rel) <= kPoseTolerance && at_slot && st_->stock[hh][static_cast<std::size_t>(s)] > 0) {
        --st_->stock[hh][static_cast<std::size_t>(s)];
        holding_[hh] = s;
      }
    }
    // The cutter fires with the yarn wrapped round its warp pair and pulled down (the gripper in the warp):
    // the knot is tied at the knot under the head, unless it slips off.
    if (out.cutter[hh] && !cutter_[hh] && holding_[hh] >= 0) {
      const int k = knot_under(h, carriage);
      if (in_warp(knotter) && k >= 0 && rng.uniform() >= k_.miss_probability) tie(st_->row, k, holding_[hh], false);
      holding_[hh] = -1;  // cut: the rest of the yarn stays in the magazine's feed
    }
    if (!out.gripper_close[hh]) holding_[hh] = -1;  // opened: whatever it held drops
    gripper_[hh] = out.gripper_close[hh];
    cutter_[hh] = out.cutter[hh];
  }
  // The weaver.
  if (pedal_left_ > 0) --pedal_left_;
  if (task_pending_ && --task_left_ <= 0) {
    task_pending_ = false;
    switch (task_.kind) {
      case WeaverTask::Kind::kReload:
        if (task_.head >= 0 && task_.head < m_.heads && task_.slot >= 0 && task_.slot < m_.slots) {
          st_->stock[static_cast<std::size_t>(task_.head)][static_cast<std::size_t>(task_.slot)] = m_.knots_per_slot;
        }
        break;
      case WeaverTask::Kind::kCheckKnot:
        // A knot that is there is left alone (it was tied before the power failed); a missing one is tied.
        if (task_.knot >= 0 && task_.knot < m_.knots_per_row && cell(st_->row, task_.knot).ties > 0) break;
        [[fallthrough]];
      case WeaverTask::Kind::kTieByHand:
        if (task_.knot >= 0 && task_.knot < m_.knots_per_row) tie(st_->row, task_.knot, task_.slot, true);
        // At the head the weaver sees an empty slot (why it missed) and fills it.
        if (task_.head >= 0 && task_.head < m_.heads && task_.slot >= 0 && task_.slot < m_.slots &&
            st_->stock[static_cast<std::size_t>(task_.head)][static_cast<std::size_t>(task_.slot)] <= 0) {
          st_->stock[static_cast<std::size_t>(task_.head)][static_cast<std::size_t>(task_.slot)] = m_.knots_per_slot;
        }
        break;
    }
    ++tasks_done_;
    pedal_left_ = kPedalTicks;
  }
}

void SimKnotter::inputs(const std::array<double, hal::kMaxAxes>& position, hal::DigitalInputs& io) noexcept {
  const double carriage = position[hal::index(hal::CoreAxis::kCarriage)];
  for (int h = 0; h < m_.heads; ++h) {
    const int k = knot_under(h, carriage);
    io.yarn_present[static_cast<std::size_t>(h)] = k >= 0 && cell(st_->row, k).ties > 0;
  }
  io.row_knotted = pedal_left_ > 0;
}

void SimKnotter::on_weft() noexcept {
  if (st_->row_has_knots == 0) return;
  st_->row_has_knots = 0;
  ++st_->row;
}

void SimKnotter::ask(const WeaverTask& t) noexcept {
  task_ = t;
  task_pending_ = true;
  task_left_ = std::max<std::int64_t>(1, std::llround(k_.weaver_s / period_s_));
}

void SimKnotter::yarn_out(int head, int slot) noexcept {
  if (head < 0 || head >= m_.heads || slot < 0 || slot >= m_.slots) return;
  st_->stock[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)] = 0;
}

}  // namespace loom::sim_hal
