// See row_time.hpp.
#include "loom/sequencer/row_time.hpp"

#include "loom/sequencer/row_knotter.hpp"

namespace loom::sequencer {

std::optional<hal::Tick> ideal_row_knotting_ticks(const SequencerConfig& cfg, double carriage_travel_m,
                                                  std::uint32_t row0, hal::Tick max_ticks) {
  if (cfg.heads.program == nullptr || cfg.heads.cycle == nullptr) return std::nullopt;
  const KnotGuard guard = knot_guard(cfg.heads);
  RowKnotter heads;
  heads.configure(cfg.heads, &guard, cfg.period_s, cfg.carriage_home_m, cfg.carriage, cfg.stale_timeout_s);
  // As the sequencer begins a row: the carriage at the left selvedge, where the last sweep ended (and where
  // it waits before a first row); knotted, it goes to the row's sweep start.
  const double start_m = 0.0;
  const double return_to_m = row_sweep_starts_left(true, row0) ? 0.0 : carriage_travel_m;
  hal::HalOutputs cmd{};
  hal::HalInputs in{};
  cmd.axes[hal::index(hal::CoreAxis::kCarriage)].target_position = cfg.carriage_home_m + start_m;
  KnotCounters counters{};
  heads.begin(row0, counters, return_to_m, 0, cmd);
  RowKnotter::StepInputs s;
  for (hal::Tick t = 0; t < max_ticks; ++t) {
    for (std::size_t a = 0; a < hal::kMaxAxes; ++a) in.axes[a].position = cmd.axes[a].target_position;
    in.io.yarn_present = cmd.io.gripper_close;  // a closed gripper holds its yarn: every knot tied
    switch (heads.step(t, in, cmd, counters, s)) {
      case RowKnotter::Status::kDone:
        return t;
      case RowKnotter::Status::kFault:
        return std::nullopt;
      default:
        break;
    }
  }
  return std::nullopt;
}

}  // namespace loom::sequencer
