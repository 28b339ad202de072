// The beat held in its band by the load cell: a per-beat regulator of the crank's speed at the beat.
//
// The beater's force on the fell is inertial (the linkage decelerates the comb and its mass does the
// beating), so at a constant crank speed it scales with the speed squared: F = g·s², where s is the
// beat's speed relative to the recipe's crank speed and g the force the warp returns at the recipe's speed
// (the "gain" of that place of the warp now — uneven across the width, drifting as the carpet grows).
// After each beat, its measured peak gives g = F / s²; the next beat's speed is s = √(F* / ĝ), with ĝ the
// gain predicted for the next beat's carriage position and F* the middle of the band. The prediction
// remembers every position's gain from the rows before (the tension across the width is mostly the same
// at the same place) and corrects it by the drift seen since: the ratio of the newest beat's gain to what
// was remembered at its own position. In the first row nothing is remembered yet and the newest beat's
// gain stands for the next position's. Bounded: s stays within the speed scale's bounds.
//
// How a speed reaches the crank (SweepClock, below): the beat sweep is one precomputed move of the master
// phase (motion's ProfileSet::crank_sweep, beats × 2π, the crank law and the carriage cam on it). The
// regulator never re-plans it: it samples it at a warped time τ with dτ/dt = s, which plays the same path
// — the same crank phases, the same warp window, the same cam — faster or slower. Each beat's speed is
// reached on its approach — from the warp entry to half-way (in crank phase) to the fell: the carriage at
// rest, the comb in the warp but well short of the fell, whose approach is about quadratic in the phase
// near the dead centre — and given back on its way out, from half-way after the fell to half-way through
// the cam margin after the warp exit (the carriage still at rest), each with a jerk-limited change (a
// triangular acceleration). Hence:
//   - the warp window is never moved: it is a set of crank phases, and the path through them is the same;
//   - every contact with the fell happens at one constant speed, and the force goes with its square;
//   - from then to the next warp entry the crank runs at the recipe's speed, s = 1 exactly, so everything
//     the carriage does is as open loop: its steps, the dwell that lets it settle before the next warp entry,
//     and so the cam margin's time; the interlocks and the carriage's limits see what they always see (a
//     faster crank would shorten the carriage's settling time: the safety campaign found it with a lagging
//     carriage and a torque-limited crank when the speed changed in the dwell before the warp entry);
//   - the speed changes respect the recipe's crank acceleration and jerk (the run-up's own limits): a
//     change that does not fit its approach is cut to what does; the bounds are narrowed at configure
//     time so that every return to 1 fits its window;
//   - the run-up and the braking are played at s = 1 exactly.
// Without a measured beat (no load cell) nothing changes: s stays 1 and τ is the tick time, bit for bit.
// RT rules: fixed arrays, no allocation; the regulator's work is per beat (after_beat), the clock's per
// tick is a few multiplications.
#pragma once

#include <array>
#include <cstdint>

#include "loom/hal/types.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/sequencer/row_stats.hpp"

namespace loom::sequencer {

struct BeatRegulatorConfig {
  // Closed loop whenever the beats are measured (the machine has a load cell); false keeps the loom open
  // loop even with one (tests compare the two).
  bool enabled = true;
  // Bounds of the beat's crank speed relative to the recipe's: ±15 % moves the force by −28 % / +32 %.
  // Narrowed at configure time to what the window for the return to the recipe's speed allows.
  double min_speed_scale = 0.85;
  double max_speed_scale = 1.15;
  // Weight of the newest beat in a position's remembered gain, and in the drift since the positions were
  // last beaten (exponential averages: lower weights filter more of the beat-to-beat noise).
  double memory_weight = 0.5;
  double drift_weight = 0.3;
};

// What the regulator decides from: the band's middle and the bounds actually in force.
struct BeatRegulatorLimits {
  double target_n = 90.0;
  double min_scale = 1.0, max_scale = 1.0;
  double max_step = 0.0;  // the largest speed change one beat's approach allows (informational)
};

class BeatRegulator {
 public:
  // Configure-time. `positions` carriage positions per row (≤ kMaxBeatsPerRow); everything remembered is
  // forgotten (a new recipe may have other positions).
  void configure(const BeatRegulatorConfig& cfg, const BeatRegulatorLimits& limits, int positions) noexcept;

  // RT-safe. The speed scale for the first beat of a sweep, at carriage position `position`.
  double first_beat(int position) const noexcept;
  // RT-safe, once per beat. Beat at `position` beaten at `scale`; `peak_n` its peak when `measured`. Returns
  // the scale for the next beat, at `next_position`.
  double after_beat(int position, double scale, bool measured, double peak_n, int next_position) noexcept;

  const BeatRegulatorLimits& limits() const noexcept { return limits_; }
  bool enabled() const noexcept { return cfg_.enabled; }
  std::uint32_t beats_learned() const noexcept { return learned_; }
  double drift() const noexcept { return drift_; }

 private:
  double scale_for(double gain) const noexcept;             // √(F*/g), bounded
  bool predict(int position, double& gain) const noexcept;  // false: nothing to go by

  BeatRegulatorConfig cfg_{};
  BeatRegulatorLimits limits_{};
  int positions_ = 0;
  std::array<double, kMaxBeatsPerRow> gain_{};  // remembered gain per position (N at scale 1)
  std::array<bool, kMaxBeatsPerRow> known_{};
  double drift_ = 1.0;      // the gain now over the remembered gain
  double last_gain_ = 0.0;  // the newest beat's
  int last_position_ = -1;
  std::uint32_t learned_ = 0;
};

// The beat sweep's warped clock (see the top of this file). Times are seconds since the sweep began.
class SweepClock {
 public:
  // Configure-time, and at a row boundary that adopts a new recipe (bounded, no allocation). The
  // master-phase windows of every beat, from the profile set; returns the bounds narrowed to what the
  // return to the recipe's speed allows, and the largest change a beat's approach allows (at the fastest
  // beat). `period_s`: the tick.
  BeatRegulatorLimits configure(const motion::ProfileSet& p, double period_s, const BeatRegulatorConfig& cfg,
                                double target_n) noexcept;

  // RT-safe. A sweep begins at tick `t0` at scale 1.
  void start(hal::Tick t0) noexcept;
  // RT-safe. The sweep has ended (or was cut by a fault): active() is false until the next start().
  void stop() noexcept { pending_ = returning_ = active_ = false; }
  // RT-safe. Whether this sweep's clock differs from the tick time: a change asked for or made. While not,
  // the caller samples the sweep at the tick time itself and need not call time_at() or advance().
  bool active() const noexcept { return active_; }
  // RT-safe. The time at which to sample the sweep move at tick `now` (the tick time while the scale is 1).
  // After a change, τ = c + s1·u, one multiply-add (c folds the change's own integral in).
  double time_at(hal::Tick now) const noexcept {
    const double u = static_cast<double>(now - seg_tick_) * dt_;
    return u < T_ ? time_in_change(u) : c_ + s1_ * u;
  }
  // RT-safe. Beat `beat` (0-based; beats_per_row() or more: nothing, the braking is at scale 1) is to be
  // beaten at `scale`: the change happens on that beat's approach, once the master has reached it, and the
  // return to 1 after its contact.
  void request(int beat, double scale) noexcept;
  // RT-safe, every tick of the sweep while active(), with the master phase just sampled at `now`: starts a
  // requested change, or the return to 1, when the master is inside its window.
  void advance(hal::Tick now, double master) noexcept {
    if ((pending_ && master >= pending_from_) || (returning_ && master >= return_from_))
      advance_slow(now, master);
  }
  // The scale the sweep is at or going to (the last change's target).
  double scale() const noexcept { return s1_; }
  // The scale the latest beat met the fell at (its approach's target, as far as it got; 1 before any).
  double beat_scale() const noexcept { return beat_scale_; }
  bool warped() const noexcept { return warped_; }

 private:
  void advance_slow(hal::Tick now, double master) noexcept;
  // Starts a change to `target` that ends by master phase `until` (cut to what fits); false: none started.
  bool begin_change(hal::Tick now, double master, double target, double until) noexcept;
  double time_in_change(double u) const noexcept;
  double window_from(int beat) const noexcept;  // master phase where beat's approach window opens
  double window_to(int beat) const noexcept;    // and where it closes
  double return_from(int beat) const noexcept;  // where the return to 1 after beat's contact may begin
  double return_to(int beat) const noexcept;    // and where it must have ended

  double dt_ = 0.002;
  double v_ = 1.0;  // the sweep's cruise speed (master rad/s at scale 1)
  double accel_ = 0.0, jerk_ = 0.0;
  double ramp_ = 0.0;      // master phase of the run-up (and of the braking)
  double enter_ = 0.0;     // master phase of the warp entry within a turn
  double approach_ = 0.0;  // of half-way from the entry to the fell
  double depart_ = 0.0;    // of half-way from the fell to the exit
  double exit_ = 0.0;      // of the warp exit
  int beats_ = 0;
  double min_scale_ = 1.0, max_scale_ = 1.0;
  // The segment in force: from tick seg_tick_ (sweep time seg_time_), the scale goes s0_ → s1_ over T_ s;
  // after it, τ = c_ + s1_·u (u: seconds since seg_tick_).
  hal::Tick seg_tick_ = 0;
  double seg_time_ = 0.0, s0_ = 1.0, s1_ = 1.0, T_ = 0.0, c_ = 0.0;
  double beat_scale_ = 1.0;
  bool warped_ = false;     // some change has happened in this sweep
  bool pending_ = false;    // a beat's change asked for, not begun
  bool returning_ = false;  // a return to 1 planned, not begun
  bool active_ = false;     // pending_ || returning_ || warped_
  double pending_scale_ = 1.0, pending_from_ = 0.0, pending_to_ = 0.0;
  int pending_beat_ = 0;
  double return_from_ = 0.0, return_to_ = 0.0;
};

}  // namespace loom::sequencer
