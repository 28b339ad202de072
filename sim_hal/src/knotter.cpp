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
// A knot's cell in one byte: bits 0-4 its slot + 1 (0: no knot), bits 5-6 its ties (up to 3), bit 7 by hand.
constexpr std::uint8_t kSlotMask = 0x1f, kTiesShift = 5, kTiesMask = 0x3, kByHand = 0x80;

KnotCell unpack(std::uint8_t b) noexcept {
  KnotCell c;
  c.slot = static_cast<std::int8_t>(static_cast<int>(b & kSlotMask) - 1);
  c.ties = static_cast<std::uint8_t>((b >> kTiesShift) & kTiesMask);
  c.by_hand = (b & kByHand) != 0;
  return c;
}

void fresh(PersistedCarpet& c, const SimKnotting& m, std::uint32_t first_row, std::size_t room) {
  c.magic = PersistedCarpet::kMagic;
  c.first_row = first_row;
  c.knots_per_row = m.knots_per_row;
  c.row = 0;
  c.row_has_knots = 0;
  c.knots_beyond = 0;
  for (auto& head : c.stock) head.fill(m.knots_per_slot);
  std::fill_n(knot_cells(c), room, std::uint8_t{0});
}
}  // namespace

// The knotter's own carpet (no sim-state file): a buffer of header and cells, grown at configure time.
class SimKnotter::OwnCarpet final : public CarpetKeeper {
 public:
  PersistedCarpet& reserve(std::size_t cells) override {
    if (cells > room_ || words_.empty()) {
      std::vector<std::uint64_t> grown((sizeof(PersistedCarpet) + cells + 7) / 8, 0);
      if (!words_.empty()) std::copy(words_.begin(), words_.end(), grown.begin());
      words_ = std::move(grown);
      room_ = cells;
    }
    return *reinterpret_cast<PersistedCarpet*>(words_.data());
  }
  std::size_t room() const noexcept override { return room_; }

 private:
  std::vector<std::uint64_t> words_;  // 8-byte aligned, as the header needs
  std::size_t room_ = 0;
};

SimKnotter::SimKnotter(const SimKnotting& m, const Knotter& k, double period_s)
    : m_(m),
      k_(k),
      period_s_(period_s),
      own_(std::make_unique<OwnCarpet>()),
      beyond_(static_cast<std::size_t>(std::max(0, m.knots_per_row)), 0) {
  keep_in(*own_, 0, false);
  holding_.fill(-1);
}

SimKnotter::~SimKnotter() = default;

// Rows the record needs for a carpet begun at production row `first_row` with `rows_knotted` rows in it.
int SimKnotter::rows_needed(std::uint32_t first_row, int rows_knotted) const noexcept {
  if (k_.carpet_rows > 0) return k_.carpet_rows;
  long long rows = 0;
  if (m_.last_row > first_row) {
    rows = static_cast<long long>(m_.last_row - first_row);
  } else {
    rows = static_cast<long long>(rows_knotted) + std::max(m_.design_rows, Knotter::kUnboundedRows);
  }
  return static_cast<int>(std::clamp<long long>(std::max<long long>(rows, rows_knotted), 1, 1'000'000));
}

void SimKnotter::keep_in(CarpetKeeper& keeper, std::uint32_t counter_rows, bool adopt,
                         std::optional<std::uint32_t> carpet_began) {
  const std::size_t width = static_cast<std::size_t>(std::max(1, m_.knots_per_row));
  const std::size_t had = keeper.room();
  const PersistedCarpet* old = had > 0 ? &keeper.reserve(had) : nullptr;
  const bool ours = adopt && old != nullptr && old->magic == PersistedCarpet::kMagic &&
                    old->knots_per_row == m_.knots_per_row && old->row >= 0 && old->row_has_knots >= 0 &&
                    (static_cast<std::size_t>(old->row) <= had / width || old->knots_beyond > 0) &&
                    (!carpet_began || old->first_row >= *carpet_began);
  const std::uint32_t first = ours ? old->first_row : counter_rows;
  const int knotted = ours ? old->row + (old->row_has_knots ? 1 : 0) : 0;
  const std::size_t rows = static_cast<std::size_t>(rows_needed(first, knotted));
  // Room for every row, never less than the keeper has (a carpet kept is never cut short).
  PersistedCarpet& c = keeper.reserve(std::max(had, rows * width));
  const std::size_t room = keeper.room();
  if (!ours) fresh(c, m_, counter_rows, room);
  st_ = &c;
  cells_ = knot_cells(c);
  capacity_rows_ = static_cast<int>(std::min<std::size_t>(room / width, rows));
  std::fill(beyond_.begin(), beyond_.end(), std::uint8_t{0});
}

void SimKnotter::persist_in(CarpetKeeper& keeper, std::uint32_t counter_rows,
                            std::optional<std::uint32_t> carpet_began) {
  keep_in(keeper, counter_rows, true, carpet_began);
  own_.reset();
}

void SimKnotter::start_at_row(std::uint32_t counter_rows) {
  if (own_) keep_in(*own_, counter_rows, false);
}

KnotCell SimKnotter::cell(int row, int knot) const noexcept {
  if (row < 0 || row >= capacity_rows_ || knot < 0 || knot >= m_.knots_per_row) return KnotCell{};
  return unpack(cells_[static_cast<std::size_t>(row) * static_cast<std::size_t>(m_.knots_per_row) +
                       static_cast<std::size_t>(knot)]);
}

std::uint8_t& SimKnotter::current(int knot) noexcept {
  if (st_->row >= capacity_rows_) return beyond_[static_cast<std::size_t>(knot)];
  return cells_[static_cast<std::size_t>(st_->row) * static_cast<std::size_t>(m_.knots_per_row) +
                static_cast<std::size_t>(knot)];
}

std::uint8_t SimKnotter::current_cell(int knot) const noexcept {
  return const_cast<SimKnotter*>(this)->current(knot);
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

void SimKnotter::tie(int knot, int slot, bool by_hand) noexcept {
  if (st_->row >= capacity_rows_) ++st_->knots_beyond;  // tied, but past the record: the check says so
  std::uint8_t& b = current(knot);
  const int ties = std::min<int>(kTiesMask, ((b >> kTiesShift) & kTiesMask) + 1);
  b = static_cast<std::uint8_t>((slot + 1) & kSlotMask) | static_cast<std::uint8_t>(ties << kTiesShift) |
      (by_hand ? kByHand : std::uint8_t{0});
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
      if (in_warp(knotter) && k >= 0 && rng.uniform() >= k_.miss_probability) tie(k, holding_[hh], false);
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
          st_->stock[static_cast<std::size_t>(task_.head)][static_cast<std::size_t>(task_.slot)] =
              m_.knots_per_slot;
        }
        break;
      case WeaverTask::Kind::kCheckKnot:
        // A knot that is there is left alone (it was tied before the power failed); a missing one is tied.
        if (task_.knot >= 0 && task_.knot < m_.knots_per_row &&
            ((current_cell(task_.knot) >> kTiesShift) & kTiesMask) > 0)
          break;
        [[fallthrough]];
      case WeaverTask::Kind::kTieByHand:
        if (task_.knot >= 0 && task_.knot < m_.knots_per_row) tie(task_.knot, task_.slot, true);
        // At the head the weaver sees an empty slot (why it missed) and fills it.
        if (task_.head >= 0 && task_.head < m_.heads && task_.slot >= 0 && task_.slot < m_.slots &&
            st_->stock[static_cast<std::size_t>(task_.head)][static_cast<std::size_t>(task_.slot)] <= 0) {
          st_->stock[static_cast<std::size_t>(task_.head)][static_cast<std::size_t>(task_.slot)] =
              m_.knots_per_slot;
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
    io.yarn_present[static_cast<std::size_t>(h)] =
        k >= 0 && ((current_cell(k) >> kTiesShift) & kTiesMask) > 0;
  }
  io.row_knotted = pedal_left_ > 0;
}

void SimKnotter::on_weft() noexcept {
  if (st_->row_has_knots == 0) return;
  st_->row_has_knots = 0;
  if (st_->row >= capacity_rows_) std::fill(beyond_.begin(), beyond_.end(), std::uint8_t{0});
  ++st_->row;
}

void SimKnotter::ask(const WeaverTask& t) noexcept {
  task_ = t;
  task_pending_ = true;
  task_left_ = std::max<std::int64_t>(1, std::llround(k_.weaver_s / period_s_));
}

void SimKnotter::reload(int head, int slot, std::int32_t knots) noexcept {
  if (head < 0 || head >= m_.heads || slot < 0 || slot >= m_.slots) return;
  st_->stock[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)] =
      knots < 0 || knots > m_.knots_per_slot ? m_.knots_per_slot : knots;
}

void SimKnotter::yarn_out(int head, int slot) noexcept {
  if (head < 0 || head >= m_.heads || slot < 0 || slot >= m_.slots) return;
  st_->stock[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)] = 0;
}

}  // namespace loom::sim_hal
