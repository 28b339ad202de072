// One control cycle, no loop inside, steps in a fixed order (LinuxCNC's motion controller pattern):
//   read inputs → sequencer (checks faults, advances the row cycle, samples profiles, interlocks)
//   → write outputs → forward the sequencer's events of the tick (BEAT, ROW, WEAVER, FAULT; never
//   decimated) and the devices' own fault reports → push a POD snapshot.
// Everything the cycle touches is allocated before the first tick.
#pragma once

#include <array>
#include <cstdint>

#include "loom/hal/hal.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/telemetry/snapshot.hpp"

namespace loom::telemetry {
class Telemetry;
}

namespace loom::firmware {

struct LoopStats {
  std::uint32_t overruns = 0;
  std::int64_t last_tick_cost_ns = 0;
  std::int64_t max_tick_cost_ns = 0;
  // Wake-up latency (actual wake − deadline), filled by a runner that measures it; 0 = not measured.
  std::int64_t wake_latency_p50_ns = 0;
  std::int64_t wake_latency_p99_ns = 0;
  std::int64_t wake_latency_max_ns = 0;
  std::int64_t last_wake_latency_ns = 0;
  std::int64_t max_wake_latency_ns = 0;
  std::int64_t tick_cost_p999_ns = 0;  // over the run so far, refreshed about once a second
  std::uint32_t events_dropped = 0;    // run events lost to a full reporter ring
};

// What telemetry reports about the loom beyond what the sequencer knows per tick: set once at
// configure time (defaults: the thesis' 80–100 N band, no following-error limit checked here).
struct TelemetryContext {
  double beat_force_min_n = 80.0;
  double beat_force_max_n = 100.0;
  std::uint32_t rows_target = 0;                              // 0 = until stopped / unknown
  std::array<double, hal::kMaxAxes> following_error_limit{};  // SI per axis; 0 = not checked
  // The knotting heads' design as magazine slots (Machine::knot_program(); null: no heads, and the
  // snapshot's knots stay empty at no cost per tick). Must outlive the loop.
  const sequencer::KnotProgram* knot_program = nullptr;
};

class ControlLoop {
 public:
  // Configure-time only. `telemetry` may be null (no publishing). With `lossless_telemetry` the cycle
  // waits for ring space instead of dropping: only for virtual time, where nothing is real-time.
  // `period_ns` is the loop's period as the config derives it (LoomConfig::timing).
  ControlLoop(hal::Hal& hal, sequencer::Sequencer& seq, telemetry::Telemetry* telemetry,
              std::int64_t period_ns, bool lossless_telemetry);

  // Configure-time only.
  void set_telemetry_context(const TelemetryContext& c) noexcept { ctx_ = c; }

  // RT-safe (unless lossless_telemetry). One tick.
  void cycle(hal::Tick now) noexcept;

  LoopStats& stats() noexcept { return stats_; }
  // The telemetry the cycle waits on for ring space (lossless, virtual time only), else nullptr: a
  // runner waits for room before the cycle so the wait is reported apart from the tick's cost.
  telemetry::Telemetry* lossless_telemetry() const noexcept { return lossless_ ? telemetry_ : nullptr; }
  const hal::HalInputs& inputs() const noexcept { return in_; }
  const hal::HalOutputs& outputs() const noexcept { return out_; }
  const telemetry::Snapshot& snapshot() const noexcept { return snap_; }

 private:
  void fill_snapshot(hal::Tick now) noexcept;
  void fill_knots() noexcept;
  void push_events(hal::Tick now) noexcept;
  void push_beat(const sequencer::BeatEvent& b, hal::Tick now) noexcept;
  void push_row(hal::Tick now) noexcept;
  void push_weaver_request(hal::Tick now) noexcept;
  void push_fault(telemetry::Event::FaultKind kind, sequencer::Fault which, int axis,
                  std::uint16_t device_code, int sensor, hal::Tick now) noexcept;
  void push_device_faults(int first_axis_reported, bool link_reported, hal::Tick now) noexcept;
  bool any_device_event() const noexcept;
  void push_event(const telemetry::Event& e) noexcept;
  void fill_event_context(telemetry::Event& e, hal::Tick now) const noexcept;
  std::uint32_t row_in_progress() const noexcept;

  hal::Hal& hal_;
  sequencer::Sequencer& seq_;
  std::size_t n_axes_;  // the machine's axes (seq_.axes().count)
  telemetry::Telemetry* telemetry_;
  std::int64_t period_ns_;
  bool lossless_;
  hal::HalInputs in_{};
  hal::HalOutputs out_{};
  telemetry::Snapshot snap_{};
  // The fault snap_'s fault code is for, so fill_snapshot looks the code up only when the fault changes.
  bool code_shown_ = false;
  sequencer::Fault shown_first_fault_ = sequencer::Fault::kNone;
  // The crank target and recipe snap_'s crank phase and beater angle were computed for.
  bool crank_shown_ = false;
  double shown_crank_target_ = 0.0;
  std::uint32_t shown_recipe_ = 0;
  LoopStats stats_{};
  TelemetryContext ctx_{};
  bool knots_shown_ = false;  // snap_.knots was filled at least once
};

}  // namespace loom::firmware
