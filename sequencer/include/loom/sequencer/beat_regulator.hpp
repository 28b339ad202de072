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
// — the same crank phases, the same warp window, the same cam — faster or slower. s changes only inside
// windows where the carriage is at rest and the beater is out of the warp (the cam's dwell before each
// warp entry, after the run-up, or between two beats at one position), with a jerk-limited change (a
// triangular acceleration) that ends before the beater enters the warp. Hence:
//   - the warp window is never moved: it is a set of crank phases, and the path through them is the same;
//   - the interlocks see what they always see: the carriage is a function of the crank phase and moves
//     only in the cam's steps, i.e. only while the beater is clear; the cam margin (in crank angle)
//     covers the crank's lag at the fastest beat (s_max × the recipe's speed: 22 ms / s_max of lag at the
//     default 20 deg and 16 rad/s), and every beat's contact happens at a constant speed;
//   - each carriage step happens at one constant master speed s·v, so its peaks are those of a step at
//     s·v: the bound s_max is at most the fastest crank the carriage's limits allow
//     (ProfileSet::carriage_peaks().max_crank_speed_rad_s, checked when the profiles were built);
//   - the speed changes respect the recipe's crank acceleration and jerk (the run-up's own limits): a
//     change that does not fit its window is cut to what does, the rest waits for the next beat;
//   - the run-up and the braking are played at s = 1 exactly (the last beat's window returns s to 1
//     before the braking begins; the bounds are narrowed at configure time so that it always can).
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
  // Narrowed at configure time to what the carriage's limits and the braking window allow.
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
  double max_step = 0.0;  // the largest speed change one carriage step's dwell allows (informational)
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
  // master-phase windows of every beat and of the braking, from the profile set; returns the bounds
  // narrowed to what the carriage and the braking window allow, and the largest step a carriage step's
  // dwell allows (at the fastest beat). `period_s`: the tick.
  BeatRegulatorLimits configure(const motion::ProfileSet& p, double period_s, const BeatRegulatorConfig& cfg,
                                double target_n) noexcept;

  // RT-safe. A sweep begins at tick `t0` at scale 1.
  void start(hal::Tick t0) noexcept;
  // RT-safe. The sweep has ended (or was cut by a fault): active() is false until the next start().
  void stop() noexcept { pending_ = active_ = false; }
  // RT-safe. Whether this sweep's clock differs from the tick time: a change asked for or made. While not,
  // the caller samples the sweep at the tick time itself and need not call time_at() or advance().
  bool active() const noexcept { return active_; }
  // RT-safe. The time at which to sample the sweep move at tick `now` (the tick time while the scale is 1).
  // After a change, τ = c + s1·u, one multiply-add (c folds the change's own integral in).
  double time_at(hal::Tick now) const noexcept {
    const double u = static_cast<double>(now - seg_tick_) * dt_;
    return u < T_ ? time_in_change(u) : c_ + s1_ * u;
  }
  // RT-safe. Beat `beat` (0-based; beats_per_row() means the braking, at scale 1) is to be beaten at
  // `scale`: the change happens in that beat's window, once the master has reached it.
  void request(int beat, double scale) noexcept;
  // RT-safe, every tick of the sweep while active(), with the master phase just sampled at `now`: starts a
  // requested change when the master is inside its window.
  void advance(hal::Tick now, double master) noexcept {
    if (pending_ && master >= pending_from_) begin_change(now, master);
  }
  // The scale the sweep is at or going to (the last change's target).
  double scale() const noexcept { return s1_; }
  bool warped() const noexcept { return warped_; }

 private:
  void begin_change(hal::Tick now, double master) noexcept;
  double time_in_change(double u) const noexcept;
  double window_from(int beat) const noexcept;  // master phase where beat's window opens
  double window_to(int beat) const noexcept;    // and where it closes

  double dt_ = 0.002;
  double v_ = 1.0;  // the sweep's cruise speed (master rad/s at scale 1)
  double accel_ = 0.0, jerk_ = 0.0;
  double ramp_ = 0.0;      // master phase of the run-up (and of the braking)
  double enter_ = 0.0;     // master phase of the warp entry within a turn
  double exit_ = 0.0;      // of the warp exit
  double step_end_ = 0.0;  // of the end of the carriage step before a turn's entry (may be < 0)
  int beats_ = 0, per_position_ = 1;
  double min_scale_ = 1.0, max_scale_ = 1.0;
  // The segment in force: from tick seg_tick_ (sweep time seg_time_), the scale goes s0_ → s1_ over T_ s;
  // after it, τ = c_ + s1_·u (u: seconds since seg_tick_).
  hal::Tick seg_tick_ = 0;
  double seg_time_ = 0.0, s0_ = 1.0, s1_ = 1.0, T_ = 0.0, c_ = 0.0;
  bool warped_ = false;  // some change has happened in this sweep
  bool pending_ = false;
  bool active_ = false;  // pending_ || warped_
  double pending_scale_ = 1.0, pending_from_ = 0.0, pending_to_ = 0.0;
};

}  // namespace loom::sequencer
