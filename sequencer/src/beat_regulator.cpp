// The per-beat force regulator and the sweep's warped clock (see beat_regulator.hpp).
#include "loom/sequencer/beat_regulator.hpp"

#include <algorithm>
#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::sequencer {

// ---------------------------------------------------------------------------------------------------
// BeatRegulator
// ---------------------------------------------------------------------------------------------------

void BeatRegulator::configure(const BeatRegulatorConfig& cfg, const BeatRegulatorLimits& limits,
                              int positions) noexcept {
  cfg_ = cfg;
  limits_ = limits;
  positions_ = std::clamp(positions, 0, kMaxBeatsPerRow);
  gain_.fill(0.0);
  known_.fill(false);
  drift_ = 1.0;
  last_gain_ = 0.0;
  last_position_ = -1;
  learned_ = 0;
}

double BeatRegulator::scale_for(double gain) const noexcept {
  if (!(gain > 0.0) || !std::isfinite(gain)) return 1.0;
  return std::clamp(std::sqrt(limits_.target_n / gain), limits_.min_scale, limits_.max_scale);
}

bool BeatRegulator::predict(int position, double& gain) const noexcept {
  if (position >= 0 && position < positions_ && known_[static_cast<std::size_t>(position)]) {
    gain = gain_[static_cast<std::size_t>(position)] *
           drift_;  // this place as remembered, moved by the drift since
    return true;
  }
  if (learned_ == 0) return false;
  gain = last_gain_;  // first row: the neighbour just beaten stands for this place
  return true;
}

double BeatRegulator::first_beat(int position) const noexcept {
  double g = 0.0;
  if (!cfg_.enabled || !predict(position, g)) return 1.0;
  return scale_for(g);
}

double BeatRegulator::after_beat(int position, double scale, bool measured, double peak_n,
                                 int next_position) noexcept {
  if (!cfg_.enabled) return 1.0;
  if (measured && std::isfinite(peak_n) && peak_n > 0.0 && scale > 0.0) {
    const double g = peak_n / (scale * scale);  // the force at the recipe's speed: F ∝ speed²
    if (position >= 0 && position < positions_) {
      const auto p = static_cast<std::size_t>(position);
      // The drift: how this place's gain has moved since it was last beaten (not from a beat just before at
      // the same place: that says nothing about the rows between).
      if (known_[p] && position != last_position_) drift_ += cfg_.drift_weight * (g / gain_[p] - drift_);
      gain_[p] = known_[p] ? gain_[p] + cfg_.memory_weight * (g - gain_[p]) : g;
      known_[p] = true;
    }
    last_gain_ = g;
    last_position_ = position;
    ++learned_;
  }
  if (learned_ == 0) return scale;  // nothing measured yet: as before
  if (next_position == last_position_)
    return scale_for(last_gain_);  // the same place again: as just measured
  double g = 0.0;
  return predict(next_position, g) ? scale_for(g) : scale;
}

// ---------------------------------------------------------------------------------------------------
// SweepClock
// ---------------------------------------------------------------------------------------------------

namespace {

// The master phase at which the crank law puts the crank at `crank`: bisection on the tabulated law,
// which is monotone (dΦc/dΦm ≥ its minimum ratio > 0). Bounded work, no allocation: a recipe adopted at a
// row boundary configures the clock inside the tick.
double master_of(const motion::CrankLaw& law, double crank) noexcept {
  if (law.spec().kind == motion::CrankLawKind::kConstant) return crank;
  double lo = crank - motion::kTwoPi, hi = crank + motion::kTwoPi;
  for (int i = 0; i < 64 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (law.phase_at(motion::Phase::from_rad(mid)) < crank ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The largest speed-scale change (either way) a window of `phase` master radians allows, played at
// cruise speed `v` × at most `s_top`, within the crank's acceleration and jerk: the change takes
// T = phase / (v·s_top) and its triangular acceleration peaks at 2·Δs·v/T with jerk 4·Δs·v/T².
double step_capacity(double phase, double v, double s_top, double accel, double jerk) noexcept {
  if (!(phase > 0.0)) return 0.0;
  const double t = phase / (v * s_top);
  return std::min(accel * t / (2.0 * v), jerk * t * t / (4.0 * v));
}

}  // namespace

BeatRegulatorLimits SweepClock::configure(const motion::ProfileSet& p, double period_s,
                                          const BeatRegulatorConfig& cfg, double target_n) noexcept {
  dt_ = period_s;
  const motion::JerkMove& sweep = p.crank_sweep();
  v_ = std::abs(sweep.peak_velocity());
  accel_ = p.spec().crank.acceleration;
  jerk_ = p.spec().crank.jerk;
  ramp_ = sweep.ramp_distance();
  const motion::WarpWindow& w = p.beatup().warp();
  const motion::CrankLaw& law = p.crank_law();
  enter_ = master_of(law, w.enter);
  // Half-way from the warp's edges to the fell: the tip is still a quarter of the warp depth or more from
  // the fell (the approach is about quadratic near the dead centre), far outside any contact.
  approach_ = master_of(law, 0.5 * (w.enter + w.fell));
  depart_ = master_of(law, 0.5 * (w.fell + w.exit));
  // Half-way from the warp exit to the start of the carriage's step (the cam margin after the exit): the
  // carriage is still at rest there, and its step and the dwell after it are played at the recipe's speed.
  exit_ = master_of(law, 0.5 * (w.exit + p.cam().window_start()));
  beats_ = p.beats_per_row();

  // Bounds: every return to 1 must fit its window (it ends before the carriage's step, the last one before
  // the braking too); one tick is lost to seeing the window open.
  double hi = std::max(1.0, cfg.max_speed_scale);
  double lo = std::min(1.0, cfg.min_speed_scale);
  const double back = return_to(beats_ - 1) - return_from(beats_ - 1);
  const auto back_fits = [&](double s) {
    const double top = std::max(s, 1.0);
    return std::abs(s - 1.0) <= step_capacity(back - v_ * top * dt_, v_, top, accel_, jerk_);
  };
  for (int i = 0; i < 60 && !back_fits(hi); ++i) hi = 1.0 + 0.5 * (hi - 1.0);
  for (int i = 0; i < 60 && !back_fits(lo); ++i) lo = 1.0 - 0.5 * (1.0 - lo);
  min_scale_ = lo;
  max_scale_ = hi;
  BeatRegulatorLimits l;
  l.target_n = target_n;
  l.min_scale = lo;
  l.max_scale = hi;
  // The largest change one beat's approach allows, at the fastest beat.
  l.max_step = step_capacity(approach_ - enter_ - v_ * hi * dt_, v_, hi, accel_, jerk_);
  start(0);
  return l;
}

void SweepClock::start(hal::Tick t0) noexcept {
  seg_tick_ = t0;
  seg_time_ = c_ = 0.0;
  s0_ = s1_ = beat_scale_ = 1.0;
  T_ = 0.0;
  warped_ = pending_ = returning_ = active_ = false;
}

double SweepClock::time_in_change(double u) const noexcept {
  // s = s0 + Δs·S(u/T), S(x) = 2x² (x ≤ ½) or 1 − 2(1 − x)², whose integral from 0 is I(x).
  const double x = u / T_;
  const double y = 1.0 - x;
  const double integral = x <= 0.5 ? (2.0 / 3.0) * x * x * x : x - 0.5 + (2.0 / 3.0) * y * y * y;
  return seg_time_ + s0_ * u + (s1_ - s0_) * T_ * integral;
}

double SweepClock::window_from(int beat) const noexcept {
  // Beat 0's approach may still be in the run-up, which is played as planned.
  const double turn = motion::kTwoPi * beat;
  return beat == 0 ? std::max(ramp_, enter_) : turn + enter_;
}

double SweepClock::window_to(int beat) const noexcept {
  return motion::kTwoPi * beat + approach_;
}

double SweepClock::return_from(int beat) const noexcept {
  return motion::kTwoPi * beat + depart_;
}

double SweepClock::return_to(int beat) const noexcept {
  // Before the carriage's step, or the braking: each carriage step and its settling are as open loop.
  return std::min(motion::kTwoPi * beat + exit_, motion::kTwoPi * beats_ - ramp_);
}

void SweepClock::request(int beat, double scale) noexcept {
  if (beat < 0 || beat >= beats_) return;  // after the last beat: its return to 1 is already planned
  pending_scale_ = std::clamp(scale, min_scale_, max_scale_);
  pending_beat_ = beat;
  pending_from_ = window_from(beat);
  pending_to_ = window_to(beat);
  pending_ = pending_scale_ != 1.0;  // the recipe's speed: the return after the last beat is there already
  if (!pending_) beat_scale_ = 1.0;
  active_ = pending_ || returning_ || warped_;
}

void SweepClock::advance_slow(hal::Tick now, double master) noexcept {
  if (returning_ && master >= return_from_) {
    returning_ = false;
    begin_change(now, master, 1.0, return_to_);
  }
  if (pending_ && master >= pending_from_) {
    pending_ = false;
    const bool changed = begin_change(now, master, pending_scale_, pending_to_);
    beat_scale_ = s1_;  // what this beat meets the fell at (its change is over before the contact)
    if (changed) {
      // Whatever speed the beat is beaten at, it is back at the recipe's before the carriage may move.
      returning_ = true;
      return_from_ = return_from(pending_beat_);
      return_to_ = return_to(pending_beat_);
    }
  }
  active_ = pending_ || returning_ || warped_;
}

bool SweepClock::begin_change(hal::Tick now, double master, double target, double until) noexcept {
  // The scale now: a change before this one has ended before its window closed, so this is s1_ (computed
  // in full all the same: a change never starts from a speed the crank is not at).
  const double u = static_cast<double>(now - seg_tick_) * dt_;
  double s_now = s1_;
  if (u < T_) {
    const double x = u / T_;
    s_now = s0_ + (s1_ - s0_) * (x <= 0.5 ? 2.0 * x * x : 1.0 - 2.0 * (1.0 - x) * (1.0 - x));
  }
  const double avail = until - master;
  if (!(avail > 0.0) || target == s_now) return false;  // the window has passed (or nothing to change)
  // Cover at most the window's remaining phase: ∫s dt over the change is T·(s0 + s1)/2 ≤ T·max(s0, s1).
  const double t = avail / (v_ * std::max(s_now, target));
  const double room = std::min(accel_ * t / (2.0 * v_), jerk_ * t * t / (4.0 * v_));
  const double ds = std::clamp(target - s_now, -room, room);
  if (ds == 0.0) return false;
  seg_time_ = time_at(now);
  seg_tick_ = now;
  s0_ = s_now;
  s1_ = s_now + ds;
  T_ = t;
  // After the change τ = seg_time + s0·T + Δs·T/2 + s1·(u − T) = c + s1·u.
  c_ = seg_time_ + (s0_ - s1_) * T_ * 0.5;
  warped_ = true;
  return true;
}

}  // namespace loom::sequencer
