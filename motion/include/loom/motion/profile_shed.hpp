// Shedding timing: the two heald-frame pistons are switched together at the start of a shed change,
// and their end sensors must confirm inside a window — not before the frames can physically have
// travelled (a stuck or miswired sensor), not after the timeout (no air, a jammed frame) — with the
// moving frames leaving their start sensors early (valve and air present), a debounce on the final
// pattern, and a settle time for the frames to stop bouncing before the shuttle is thrown.
#pragma once

#include <cstdint>

namespace loom::motion {

struct ShedSpec {
  double piston_travel_s = 0.25;    // nominal frame stroke time at supply pressure
  double earliest_fraction = 0.4;   // confirming before this fraction of the stroke time is a sensor fault
  double release_timeout_s = 0.15;  // a moving frame must have left its start end sensor by then
  double timeout_s = 1.5;           // the shed must be confirmed by then
  // The confirmed pattern must hold this long (contact bounce). 0 when the caller already debounces
  // its inputs, as the sequencer does (timing.debounce_ticks).
  double debounce_s = 0.0;
  double settle_s = 0.02;  // after confirmation, before the pick (frames bounce on the stops)
};

// Configure-time only. Throws MotionError(kInvalidInput) naming the field (its config key) when a
// value is out of range or the windows contradict each other (e.g. earliest confirmation after the
// timeout, release timeout after the timeout).
void validate(const ShedSpec& spec);

struct PistonEnds {
  bool extended = false;
  bool retracted = false;
};

enum class ShedVerdict : std::uint8_t {
  kMoving,       // frames on their way, nothing wrong yet
  kSettling,     // confirmed; waiting settle_s before the pick
  kOpen,         // confirmed and settled: the pick may start
  kTooEarly,     // fault: the end pattern appeared faster than the frames can move
  kNotReleased,  // fault: a frame that must move was never seen off its start sensor
  kTimeout,      // fault: not confirmed within timeout_s
};
const char* shed_verdict_name(ShedVerdict v);  // RT-safe
constexpr bool is_fault(ShedVerdict v) {       // RT-safe
  return v == ShedVerdict::kTooEarly || v == ShedVerdict::kNotReleased || v == ShedVerdict::kTimeout;
}

// One shed change, judged tick by tick. Time is passed in (seconds since the valves were switched).
class ShedMonitor {
 public:
  // RT-safe. Begin a change to piston A extended = a_extend, B extended = b_extend, with the end
  // sensors as they read now; a frame already in its commanded end position does not need to move.
  void start(bool a_extend, bool b_extend, PistonEnds a_now, PistonEnds b_now) noexcept;
  // RT-safe. One tick; once a fault verdict is returned it is returned again on later calls.
  ShedVerdict update(const ShedSpec& spec, double elapsed_s, PistonEnds a, PistonEnds b) noexcept;
  // RT-safe. Time of confirmation (start of the debounced pattern), or < 0 before.
  double confirmed_at_s() const noexcept { return confirmed_at_; }

 private:
  bool a_extend_ = false, b_extend_ = false;
  bool a_moves_ = false, b_moves_ = false;
  bool a_full_stroke_ = false, b_full_stroke_ = false;  // moving from the start sensor: a whole stroke
  bool a_left_ = true, b_left_ = true;  // the frame has been seen off its start sensor (or need not move)
  double stable_since_ = -1.0;
  double confirmed_at_ = -1.0;
  ShedVerdict latched_ = ShedVerdict::kMoving;
};

}  // namespace loom::motion
