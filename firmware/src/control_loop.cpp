// The control cycle and its telemetry snapshot.
#include "loom/firmware/control_loop.hpp"

#include <cmath>
#include <cstring>

#include "loom/telemetry/telemetry.hpp"

namespace loom::firmware {
namespace {
template <std::size_t N>
void copy_name(std::array<char, N>& dst, const char* src) noexcept {
  std::size_t i = 0;
  for (; i + 1 < N && src[i] != '\0'; ++i) dst[i] = src[i];
  for (; i < N; ++i) dst[i] = '\0';
}
}  // namespace

ControlLoop::ControlLoop(hal::Hal& hal, sequencer::Sequencer& seq, telemetry::Telemetry* telemetry,
                         double period_s, bool lossless_telemetry)
    : hal_(hal),
      seq_(seq),
      telemetry_(telemetry),
      period_ns_(static_cast<std::int64_t>(std::llround(period_s * 1e9))),
      lossless_(lossless_telemetry) {}

void ControlLoop::cycle(hal::Tick now) noexcept {
  hal_.read(now, in_);
  seq_.step(now, in_, out_);
  hal_.write(now, out_);
  if (telemetry_ != nullptr) {
    fill_snapshot(now);
    if (lossless_) {
      telemetry_->push_waiting(snap_);
    } else {
      telemetry_->push(snap_);
    }
  }
}

void ControlLoop::fill_snapshot(hal::Tick now) noexcept {
  telemetry::Snapshot& s = snap_;
  s.tick = now;
  s.period_ns = period_ns_;
  copy_name(s.state, sequencer::state_name(seq_.state()));
  const sequencer::Fault f = seq_.first_fault();
  copy_name(s.first_fault, f == sequencer::Fault::kNone ? "" : sequencer::fault_name(f));
  s.first_fault_code = sequencer::fault_code(f);
  s.row = seq_.counters().rows;
  s.pick = seq_.counters().picks;
  s.beat = seq_.counters().beats;
  s.crank_phase_rad = seq_.commanded_crank_phase();
  s.beater_angle_rad = seq_.commanded_rocker_angle();
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
    telemetry::AxisSample& a = s.axes[i];
    a.position = in_.axes[i].position;
    a.velocity = in_.axes[i].velocity;
    a.target = out_.axes[i].target_position;
    a.following_error = a.target - a.position;
    a.effort = in_.axes[i].effort;
    a.drive_state = static_cast<std::uint8_t>(in_.axes[i].state);
    a.request = static_cast<std::uint8_t>(out_.axes[i].request);
  }
  s.outputs = static_cast<std::uint8_t>((out_.io.piston_a_extend ? 1 : 0) | (out_.io.piston_b_extend ? 2 : 0));
  const auto& io = in_.io;
  s.inputs = static_cast<std::uint8_t>(
      (io.piston_a_extended ? 1 : 0) | (io.piston_a_retracted ? 2 : 0) | (io.piston_b_extended ? 4 : 0) |
      (io.piston_b_retracted ? 8 : 0) | (io.shuttle_at_left ? 16 : 0) | (io.shuttle_at_right ? 32 : 0) |
      (io.estop_ok ? 64 : 0));
  s.overruns = stats_.overruns;
  s.tick_cost_ns = stats_.last_tick_cost_ns;
  s.max_tick_cost_ns = stats_.max_tick_cost_ns;
  s.telemetry_dropped = static_cast<std::uint32_t>(telemetry_->dropped());
}

}  // namespace loom::firmware
