// What one row took: the time split shed/pick/beat and each beat's carriage position and peak force,
// filled while the row is woven and summarised when it ends. Fixed size (kMaxBeatsPerRow), so the RT
// path never allocates; the configuration must refuse a recipe with more beats per row than that.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include "loom/hal/types.hpp"

namespace loom::sequencer {

// Fixed capacities of the sequencer, checked by the configuration (sequencer::validate).
inline constexpr int kMaxBeatsPerRow = 256;

struct BeatRecord {
  float x_m = 0.0f;           // carriage position (beater's left edge from the left selvedge)
  float peak_force_n = 0.0f;  // peak load-cell force during this beat (0 when no load cell)
  float speed_scale = 1.0f;   // its crank speed over the recipe's (the beat regulator's choice; 1 open loop)
};

struct RowStats {
  std::uint32_t row = 0;  // 1-based number of the row just completed
  hal::Tick shed_ticks = 0, pick_ticks = 0, beat_ticks = 0, total_ticks = 0;  // shed/pick summed over picks
  hal::Tick knotting_ticks = 0;  // knotting mode: how long the weaver knotted before this row (not in total)
  // Knotting heads: the machine's knotting time (in total), the time waiting for the weaver's hand (in
  // total), and the row's knots tied by the heads, retried, and tied by the weaver.
  hal::Tick knot_ticks = 0, weaver_ticks = 0;
  int knots_tied = 0, knots_retried = 0, knots_by_hand = 0;
  int beats = 0;
  int carriage_steps = 0;
  bool force_measured = false;
  double force_min_n = 0.0, force_mean_n = 0.0, force_max_n = 0.0;
  std::array<BeatRecord, kMaxBeatsPerRow> beat{};  // first `beats` entries
};

// Fills a RowStats as the row goes. RT-safe throughout.
class RowRecorder {
 public:
  bool started() const noexcept { return started_; }
  // Begin row `row` (1-based) at `now`; a row that is already started is left alone, so every path
  // into a row (a shed, a resumed pick, a resumed sweep) can call it.
  void begin(std::uint32_t row, hal::Tick now) noexcept {
    if (started_) return;
    started_ = true;
    start_ = now;
    stats_ = RowStats{};
    stats_.row = row;
  }
  void add_shed(hal::Tick ticks) noexcept { stats_.shed_ticks += ticks; }
  void set_knotting(hal::Tick ticks) noexcept { stats_.knotting_ticks = ticks; }
  void set_knot_counts(int tied, int retried, int by_hand) noexcept {
    stats_.knots_tied = tied;
    stats_.knots_retried = retried;
    stats_.knots_by_hand = by_hand;
  }
  void set_knots(hal::Tick knot_ticks, hal::Tick weaver_ticks, int tied, int retried, int by_hand) noexcept {
    stats_.knot_ticks = knot_ticks;
    stats_.weaver_ticks = weaver_ticks;
    stats_.knots_tied = tied;
    stats_.knots_retried = retried;
    stats_.knots_by_hand = by_hand;
  }
  void add_pick(hal::Tick ticks) noexcept { stats_.pick_ticks += ticks; }
  void beat_at(int k, double x_m) noexcept {
    if (k >= 0 && k < kMaxBeatsPerRow) stats_.beat[static_cast<std::size_t>(k)].x_m = static_cast<float>(x_m);
  }
  void speed(int k, float scale) noexcept {
    if (k >= 0 && k < kMaxBeatsPerRow) stats_.beat[static_cast<std::size_t>(k)].speed_scale = scale;
  }
  void force(int k, double f_n) noexcept {
    if (k < 0 || k >= kMaxBeatsPerRow) return;
    BeatRecord& b = stats_.beat[static_cast<std::size_t>(k)];
    b.peak_force_n = std::max(b.peak_force_n, static_cast<float>(f_n));
    stats_.force_measured = true;
  }
  const RowStats& stats() const noexcept { return stats_; }
  // End the row: fill the totals and the force summary, return the finished stats.
  const RowStats& finish(hal::Tick now, hal::Tick beat_ticks, int beats, int carriage_steps) noexcept {
    started_ = false;
    stats_.beat_ticks = beat_ticks;
    stats_.total_ticks = now - start_;
    stats_.beats = beats;
    stats_.carriage_steps = carriage_steps;
    const int n = std::min(beats, kMaxBeatsPerRow);
    if (stats_.force_measured && n > 0) {
      double lo = 1e300, hi = 0.0, sum = 0.0;
      for (int k = 0; k < n; ++k) {
        const double f = stats_.beat[static_cast<std::size_t>(k)].peak_force_n;
        lo = std::min(lo, f);
        hi = std::max(hi, f);
        sum += f;
      }
      stats_.force_min_n = lo;
      stats_.force_max_n = hi;
      stats_.force_mean_n = sum / n;
    }
    return stats_;
  }

 private:
  bool started_ = false;
  hal::Tick start_ = 0;
  RowStats stats_{};
};

}  // namespace loom::sequencer
