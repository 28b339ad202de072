// One control cycle, no loop inside, steps in a fixed order (LinuxCNC's motion controller pattern):
//   read inputs → sequencer (checks faults, advances the row cycle, samples profiles, interlocks)
//   → write outputs → push a POD telemetry snapshot.
// Everything the cycle touches is allocated before the first tick.
#pragma once

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
  // Written by the runner in real time (0 in virtual time): how late the loop woke after its deadline.
  std::int64_t last_wake_latency_ns = 0;
  std::int64_t max_wake_latency_ns = 0;
  std::int64_t wake_latency_p99_ns = 0;  // over the run so far, refreshed about once a second
  std::int64_t tick_cost_p999_ns = 0;    // likewise
  std::uint32_t events_dropped = 0;      // run events lost to a full reporter ring
};

class ControlLoop {
 public:
  // Configure-time only. `telemetry` may be null (no publishing). With `lossless_telemetry` the cycle
  // waits for ring space instead of dropping: only for virtual time, where nothing is real-time.
  ControlLoop(hal::Hal& hal, sequencer::Sequencer& seq, telemetry::Telemetry* telemetry, double period_s,
              bool lossless_telemetry);

  // RT-safe (unless lossless_telemetry). One tick.
  void cycle(hal::Tick now) noexcept;

  LoopStats& stats() noexcept { return stats_; }
  const hal::HalInputs& inputs() const noexcept { return in_; }
  const hal::HalOutputs& outputs() const noexcept { return out_; }
  const telemetry::Snapshot& snapshot() const noexcept { return snap_; }

 private:
  void fill_snapshot(hal::Tick now) noexcept;

  hal::Hal& hal_;
  sequencer::Sequencer& seq_;
  telemetry::Telemetry* telemetry_;
  std::int64_t period_ns_;
  bool lossless_;
  hal::HalInputs in_{};
  hal::HalOutputs out_{};
  telemetry::Snapshot snap_{};
  LoopStats stats_{};
};

}  // namespace loom::firmware
