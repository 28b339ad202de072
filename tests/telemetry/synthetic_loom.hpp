// A scripted stand-in for the RT loop: the snapshot of any tick of a regular weaving run, computed in
// closed form from the tick alone. Tests use it both to feed the publisher and as the independent
// truth of which state and counters each tick must show.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include "loom/hal/types.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/telemetry/snapshot.hpp"
#include "loomlcm/design_t.hpp"

namespace loom::telemetry::test_support {

struct WeaveScript {
  std::int64_t shed_ticks = 10;    // shed change
  std::int64_t pick_ticks = 20;    // shuttle crossing; the pick counts when it ends
  std::int64_t beats_per_row = 4;  // crank turns per row, one beat each
  std::int64_t ticks_per_beat = 15;
  std::int64_t row_done_ticks = 5;  // counters persisted; the row counts when this ends
  std::int64_t period_ns = 2'000'000;
  std::int64_t fault_at_tick = -1;  // from this tick on: state "fault", first fault latched

  std::int64_t row_ticks() const {
    return shed_ticks + pick_ticks + beats_per_row * ticks_per_beat + row_done_ticks;
  }
  std::int64_t ticks_for_rows(std::int64_t rows) const { return rows * row_ticks(); }
};

// The snapshot carries the sequencer's enums as bytes.
inline std::uint8_t byte_of(sequencer::State s) {
  return static_cast<std::uint8_t>(s);
}
inline std::uint8_t byte_of(sequencer::Fault f) {
  return static_cast<std::uint8_t>(f);
}

// State at `tick` (before a fault): shed → pick → beat_sweep → row_end, repeating.
inline sequencer::State script_state(const WeaveScript& w, std::int64_t tick) {
  const std::int64_t in_row = tick % w.row_ticks();
  if (in_row < w.shed_ticks) return sequencer::State::kShed;
  if (in_row < w.shed_ticks + w.pick_ticks) return sequencer::State::kPick;
  if (in_row < w.row_ticks() - w.row_done_ticks) return sequencer::State::kBeatSweep;
  return sequencer::State::kRowEnd;
}

inline Snapshot script_snapshot(const WeaveScript& w, std::int64_t tick) {
  const bool faulted = w.fault_at_tick >= 0 && tick >= w.fault_at_tick;
  // Counters freeze at the fault: the loop keeps them, it does not reset them.
  const std::int64_t t = faulted ? w.fault_at_tick : tick;
  const std::int64_t row = t / w.row_ticks();
  const std::int64_t in_row = t % w.row_ticks();
  const std::int64_t beat_start = w.shed_ticks + w.pick_ticks;
  const std::int64_t beats_in_row =
      in_row < beat_start ? 0 : std::min((in_row - beat_start) / w.ticks_per_beat, w.beats_per_row);

  Snapshot s;
  s.tick = tick;
  s.period_ns = w.period_ns;
  s.state = byte_of(faulted ? sequencer::State::kFault : script_state(w, t));
  if (faulted) {
    s.first_fault = s.stopped_by = byte_of(sequencer::Fault::kEStop);
    s.first_fault_code = 0x1001;
  }
  s.row = static_cast<std::uint32_t>(row);
  s.row_in_progress = static_cast<std::uint32_t>(row + 1);
  s.pick = static_cast<std::uint32_t>(row + (in_row >= beat_start ? 1 : 0));
  s.beat = static_cast<std::uint32_t>(row * w.beats_per_row + beats_in_row);
  const double beat_progress =
      in_row < beat_start ? 0.0
                          : static_cast<double>(in_row - beat_start) / static_cast<double>(w.ticks_per_beat);
  s.crank_phase_rad = std::fmod(beat_progress, 1.0) * 2.0 * std::numbers::pi;
  s.axis_count = 3;  // the default loom's axes
  for (std::size_t i = 0; i < s.axis_count; ++i) {
    AxisSample& a = s.axes[i];
    a.position = static_cast<double>(tick) * 1e-3 * static_cast<double>(i + 1);
    a.target = a.position + 1e-4;
    a.following_error = a.target - a.position;
    a.drive_state = static_cast<std::uint8_t>(hal::DriveState::kOperationEnabled);
    a.request = static_cast<std::uint8_t>(hal::AxisRequest::kEnable);
  }
  s.tick_cost_ns = 10'000 + (tick % 7) * 100;
  s.max_tick_cost_ns = 10'600;
  return s;
}

// A DESIGN message: design "rug.csv", 6 rows, two colours (R madder, B), row 1 woven, carrying row 1
// (knotted last) and row 2 (next) with the given knots.
inline loomlcm::design_t design_message(const std::string& loom_id,
                                        std::vector<std::vector<std::int16_t>> knots) {
  loomlcm::design_t d{};
  d.loom_id = loom_id;
  d.name = "rug.csv";
  d.width = static_cast<std::int32_t>(knots.at(0).size());
  d.height = 6;
  d.rows_done = 1;
  d.next_row = 2;
  d.repeat = 1;
  d.n_colours = 2;
  d.code = {"R", "B"};
  d.colour_name = {"madder", ""};
  d.rgb = {0x9b1b30, 0x1d3f8a};
  d.n_rows = static_cast<std::int16_t>(knots.size());
  d.row_number = {1, 2};
  d.next_index = 1;
  d.knots = std::move(knots);
  return d;
}

}  // namespace loom::telemetry::test_support
