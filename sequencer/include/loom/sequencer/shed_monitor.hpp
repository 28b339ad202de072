// The sequencer's judge of one shed change. End sensors are evidence, not truth: the shed counts as
// open only on a consistent picture — each piston with exactly one end sensor on, the one its valve
// asks for, reached within a plausible time — and a sensor that is on when it cannot be is a fault:
//   - both end sensors of one piston on at once: a stuck sensor or a wiring fault (kConflict);
//   - a whole stroke confirmed faster than the profiles' window allows (earliest_fraction of the
//     nominal stroke), or faster than 80 % of the stroke time this frame showed last time (kTooEarly);
//   - a whole stroke confirmed far slower than the frame's learned stroke time (kTooLate): a frame
//     that stuck on its way, or a sensor claiming an arrival that never happened;
//   - a moving frame never seen off its start sensor (kNotReleased; both frames: kAirLost);
//   - no confirmation by the timeout (kTimeout).
// A confirmed whole stroke is not trusted before the frame can have finished it: the pick waits until
// the frame's learned (or, before one is learned, nominal) stroke time plus the settle time, so a
// sensor that sticks on a little before the frame arrives cannot open the shed under a moving frame.
// The windows themselves come from the motion profiles (motion::ShedSpec). RT-safe throughout.
#pragma once

#include <array>
#include <cstdint>

#include "loom/motion/profile_shed.hpp"

namespace loom::sequencer {

struct PistonEnds {
  bool extended = false;
  bool retracted = false;
};

enum class ShedVerdict : std::uint8_t {
  kMoving,       // frames on their way, nothing wrong yet
  kSettling,     // confirmed; waiting for the frames to settle (and to have had time to arrive)
  kOpen,         // confirmed, plausible and settled: the pick may start
  kTooEarly,     // fault: a whole stroke confirmed faster than the frame can move
  kTooLate,      // fault: a whole stroke confirmed far slower than this frame moves (stuck on the way)
  kNotReleased,  // fault: a frame that must move was never seen off its start sensor
  kAirLost,      // fault: both frames had to move and neither left its start sensor
  kTimeout,      // fault: not confirmed within the timeout
  kConflict,     // fault: one piston reads extended and retracted at once
};
const char* shed_verdict_name(ShedVerdict v) noexcept;
constexpr bool is_fault(ShedVerdict v) noexcept {
  return v != ShedVerdict::kMoving && v != ShedVerdict::kSettling && v != ShedVerdict::kOpen;
}

class ShedMonitor {
 public:
  // A whole stroke confirming faster than this fraction of the frame's last stroke time is a sensor fault.
  static constexpr double kLearnedEarliestFraction = 0.8;
  // ... and one slower than this multiple of it (plus kLateMarginS) is a frame that stuck on its way —
  // or a sensor that claims an arrival the frame never made.
  static constexpr double kLearnedLatestFactor = 1.25;
  static constexpr double kLateMarginS = 0.02;

  // RT-safe. Begin a change to piston A extended = a_extend, B extended = b_extend, with the (debounced)
  // end sensors as they read now; a frame already in its commanded end position does not need to move.
  void start(bool a_extend, bool b_extend, PistonEnds a_now, PistonEnds b_now) noexcept;
  // RT-safe. One tick, `elapsed_s` since the valves were switched; a fault verdict is returned again on
  // every later call.
  ShedVerdict update(const motion::ShedSpec& spec, double elapsed_s, PistonEnds a, PistonEnds b) noexcept;
  // RT-safe. Time of confirmation (both frames at their ends), or < 0 before.
  double confirmed_at_s() const noexcept { return confirmed_at_; }
  // Learned whole-stroke time of piston 0 (A) / 1 (B) in the extend / retract direction; < 0 unknown.
  double stroke_time_s(int piston, bool extend) const noexcept {
    return learned_[static_cast<std::size_t>(piston)][extend ? 1 : 0];
  }
  // The frames' stroke times are physical facts of this machine; forget them only when the air or the
  // frames may have changed (a re-arm after a fault).
  void forget_stroke_times() noexcept { learned_ = {{{-1.0, -1.0}, {-1.0, -1.0}}}; }

 private:
  struct Frame {
    bool extend = false;
    bool moves = false;
    bool full_stroke = false;  // moves from its start sensor: a whole stroke, timing applies
    bool left = true;          // seen off its start sensor (or need not move)
    double arrived = -1.0;     // first tick of the current at-end streak
  };
  std::array<Frame, 2> frame_{};
  std::array<std::array<double, 2>, 2> learned_{{{-1.0, -1.0}, {-1.0, -1.0}}};
  double confirmed_at_ = -1.0;
  double open_at_ = 0.0;
  ShedVerdict latched_ = ShedVerdict::kMoving;
};

}  // namespace loom::sequencer
