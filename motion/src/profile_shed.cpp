// Shed-change judging. The earliest-confirmation rule tests when the debounced pattern first appeared,
// so the debounce neither hides a sensor that was made when the valves switched nor lets a one-tick
// glitch count as one.
#include "loom/motion/profile_shed.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

[[noreturn]] void bad(const char* key, double value, const char* why) {
  std::ostringstream os;
  os << key << " = " << value << ": " << why;
  throw MotionError(ErrorCode::kInvalidInput, os.str());
}

bool at_end(PistonEnds p, bool extend) {
  return p.extended == extend && p.retracted == !extend;
}
bool on_start(PistonEnds p, bool extend) {
  return extend ? p.retracted : p.extended;
}

}  // namespace

void validate(const ShedSpec& s) {
  const auto positive = [](const char* key, double v) {
    if (!(v > 0.0) || !std::isfinite(v)) bad(key, v, "must be positive and finite");
  };
  const auto non_negative = [](const char* key, double v) {
    if (!(v >= 0.0) || !std::isfinite(v)) bad(key, v, "must be >= 0 and finite");
  };
  positive("shedding.piston_travel_s", s.piston_travel_s);
  positive("shedding.timeout_s", s.timeout_s);
  positive("shedding.release_timeout_s", s.release_timeout_s);
  non_negative("shedding.debounce_s", s.debounce_s);
  non_negative("shedding.settle_s", s.settle_s);
  if (!(s.earliest_fraction >= 0.0) || !(s.earliest_fraction < 1.0)) {
    bad("shedding.earliest_fraction", s.earliest_fraction, "must be in [0, 1)");
  }
  if (!(s.piston_travel_s + s.debounce_s < s.timeout_s)) {
    std::ostringstream os;
    os << "shedding.timeout_s = " << s.timeout_s
       << " must exceed shedding.piston_travel_s = " << s.piston_travel_s << " plus the debounce "
       << s.debounce_s << " s, or a healthy shed change times out";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  if (!(s.release_timeout_s < s.timeout_s)) {
    std::ostringstream os;
    os << "shedding.release_timeout_s = " << s.release_timeout_s
       << " must be shorter than shedding.timeout_s = " << s.timeout_s;
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
}

const char* shed_verdict_name(ShedVerdict v) {
  switch (v) {
    case ShedVerdict::kMoving:
      return "moving";
    case ShedVerdict::kSettling:
      return "settling";
    case ShedVerdict::kOpen:
      return "open";
    case ShedVerdict::kTooEarly:
      return "too_early";
    case ShedVerdict::kNotReleased:
      return "not_released";
    case ShedVerdict::kTimeout:
      return "timeout";
  }
  return "?";
}

void ShedMonitor::start(bool a_extend, bool b_extend, PistonEnds a_now, PistonEnds b_now) noexcept {
  a_extend_ = a_extend;
  b_extend_ = b_extend;
  a_moves_ = !at_end(a_now, a_extend);
  b_moves_ = !at_end(b_now, b_extend);
  a_left_ = !a_moves_;
  b_left_ = !b_moves_;
  // Only a frame that starts on its start sensor travels the whole stroke; one left mid-stroke (a
  // power cut during a shed change) may arrive as early as it likes.
  a_full_stroke_ = a_moves_ && on_start(a_now, a_extend);
  b_full_stroke_ = b_moves_ && on_start(b_now, b_extend);
  stable_since_ = -1.0;
  confirmed_at_ = -1.0;
  latched_ = ShedVerdict::kMoving;
}

ShedVerdict ShedMonitor::update(const ShedSpec& s, double t, PistonEnds a, PistonEnds b) noexcept {
  if (is_fault(latched_)) return latched_;
  if (confirmed_at_ >= 0.0) {
    // Confirmed: later sensor flicker is the interlocks' business during the pick, not a new verdict.
    return t - confirmed_at_ >= s.debounce_s + s.settle_s ? ShedVerdict::kOpen : ShedVerdict::kSettling;
  }
  const bool full_stroke = a_full_stroke_ || b_full_stroke_;
  // A frame has left once its start sensor read open on any tick: a bouncing contact can only delay
  // this verdict to the timeout, never raise it falsely.
  a_left_ = a_left_ || !on_start(a, a_extend_);
  b_left_ = b_left_ || !on_start(b, b_extend_);
  if (at_end(a, a_extend_) && at_end(b, b_extend_)) {
    if (stable_since_ < 0.0) stable_since_ = t;
    if (t - stable_since_ >= s.debounce_s) {
      if (full_stroke && stable_since_ < s.earliest_fraction * s.piston_travel_s) {
        return latched_ = ShedVerdict::kTooEarly;
      }
      confirmed_at_ = stable_since_;
      return t - confirmed_at_ >= s.debounce_s + s.settle_s ? ShedVerdict::kOpen : ShedVerdict::kSettling;
    }
  } else {
    stable_since_ = -1.0;
  }
  if (t >= s.release_timeout_s && !(a_left_ && b_left_)) {
    return latched_ = ShedVerdict::kNotReleased;
  }
  if (t > s.timeout_s) return latched_ = ShedVerdict::kTimeout;
  return ShedVerdict::kMoving;
}

}  // namespace loom::motion
