// Shed-change judging: see shed_monitor.hpp for the rules and why.
#include "loom/sequencer/shed_monitor.hpp"

#include <algorithm>

namespace loom::sequencer {
namespace {
bool at_end(PistonEnds p, bool extend) {
  return p.extended == extend && p.retracted == !extend;
}
bool on_start(PistonEnds p, bool extend) {
  return extend ? p.retracted : p.extended;
}
}  // namespace

const char* shed_verdict_name(ShedVerdict v) noexcept {
  switch (v) {
    case ShedVerdict::kMoving:
      return "moving";
    case ShedVerdict::kSettling:
      return "settling";
    case ShedVerdict::kOpen:
      return "open";
    case ShedVerdict::kTooEarly:
      return "too_early";
    case ShedVerdict::kTooLate:
      return "too_late";
    case ShedVerdict::kNotReleased:
      return "not_released";
    case ShedVerdict::kAirLost:
      return "air_lost";
    case ShedVerdict::kTimeout:
      return "timeout";
    case ShedVerdict::kConflict:
      return "conflict";
  }
  return "?";
}

void ShedMonitor::start(bool a_extend, bool b_extend, PistonEnds a_now, PistonEnds b_now) noexcept {
  const std::array<PistonEnds, 2> now{a_now, b_now};
  const std::array<bool, 2> extend{a_extend, b_extend};
  for (std::size_t i = 0; i < 2; ++i) {
    Frame& f = frame_[i];
    f.extend = extend[i];
    f.moves = !at_end(now[i], extend[i]);
    f.left = !f.moves;
    // Only a frame that starts on its start sensor travels the whole stroke; one left mid-stroke (a
    // power cut during a shed change) may arrive as early as it likes.
    f.full_stroke = f.moves && on_start(now[i], extend[i]);
    f.arrived = -1.0;
  }
  confirmed_at_ = -1.0;
  open_at_ = 0.0;
  latched_ = ShedVerdict::kMoving;
}

ShedVerdict ShedMonitor::update(const motion::ShedSpec& s, double t, PistonEnds a, PistonEnds b) noexcept {
  if (is_fault(latched_)) return latched_;
  const std::array<PistonEnds, 2> ends{a, b};
  for (const PistonEnds& e : ends) {
    if (e.extended && e.retracted) return latched_ = ShedVerdict::kConflict;
  }
  // Confirmed: later sensor flicker is the interlocks' business during the pick, not a new verdict.
  if (confirmed_at_ >= 0.0) return t >= open_at_ ? ShedVerdict::kOpen : ShedVerdict::kSettling;

  for (std::size_t i = 0; i < 2; ++i) {
    Frame& f = frame_[i];
    // A frame has left once its start sensor read open on any tick: a bouncing contact can only delay
    // this verdict to the timeout, never raise it falsely.
    f.left = f.left || !on_start(ends[i], f.extend);
    if (at_end(ends[i], f.extend)) {
      if (f.arrived < 0.0) f.arrived = t;
    } else {
      f.arrived = -1.0;
    }
  }
  if (frame_[0].arrived >= 0.0 && frame_[1].arrived >= 0.0) {
    double open_at = std::max(frame_[0].arrived, frame_[1].arrived) + s.settle_s + s.debounce_s;
    for (std::size_t i = 0; i < 2; ++i) {
      const Frame& f = frame_[i];
      if (!f.full_stroke) continue;
      const double learned = learned_[i][f.extend ? 1 : 0];
      double earliest = s.earliest_fraction * s.piston_travel_s;
      if (learned > 0.0) earliest = std::max(earliest, kLearnedEarliestFraction * learned);
      if (f.arrived < earliest) return latched_ = ShedVerdict::kTooEarly;
      // Not before the frame can have finished its stroke (learned, else nominal).
      open_at = std::max(open_at, (learned > 0.0 ? learned : s.piston_travel_s) + s.settle_s);
    }
    for (std::size_t i = 0; i < 2; ++i) {
      if (frame_[i].full_stroke) learned_[i][frame_[i].extend ? 1 : 0] = frame_[i].arrived;
    }
    confirmed_at_ = std::max(frame_[0].arrived, frame_[1].arrived);
    open_at_ = open_at;
    return t >= open_at_ ? ShedVerdict::kOpen : ShedVerdict::kSettling;
  }
  for (std::size_t i = 0; i < 2; ++i) {
    const Frame& f = frame_[i];
    const double learned = learned_[i][f.extend ? 1 : 0];
    if (f.full_stroke && learned > 0.0 && f.arrived < 0.0 &&
        t > kLearnedLatestFactor * learned + kLateMarginS) {
      return latched_ = ShedVerdict::kTooLate;
    }
  }
  if (t >= s.release_timeout_s && !(frame_[0].left && frame_[1].left)) {
    const bool both_stuck = frame_[0].moves && frame_[1].moves && !frame_[0].left && !frame_[1].left;
    return latched_ = both_stuck ? ShedVerdict::kAirLost : ShedVerdict::kNotReleased;
  }
  if (t > s.timeout_s) return latched_ = ShedVerdict::kTimeout;
  return ShedVerdict::kMoving;
}

}  // namespace loom::sequencer
