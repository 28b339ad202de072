// Seven-segment S-curve: +j, 0, -j (ramp up), cruise, -j, 0, +j (ramp down). The peak velocity is the
// largest that fits the distance; the three cases (cruise reached / acceleration limit reached /
// neither) have closed forms, so planning is a handful of flops and no iteration.
#include "loom/motion/jerk_move.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "loom/motion/errors.hpp"

namespace loom::motion {

void validate(const JerkLimits& l, const char* what) {
  const auto check = [&](double v, const char* field) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      std::ostringstream os;
      os << what << ": " << field << " limit must be positive and finite, got " << v;
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
  };
  check(l.velocity, "velocity");
  check(l.acceleration, "acceleration");
  check(l.jerk, "jerk");
}

JerkMove JerkMove::plan(double distance, const JerkLimits& l) noexcept {
  JerkMove m;
  m.distance_ = distance;
  m.sign_ = distance < 0.0 ? -1.0 : 1.0;
  const double d = std::abs(distance);
  if (!(d > 0.0) || !(l.velocity > 0.0) || !(l.acceleration > 0.0) || !(l.jerk > 0.0)) {
    return m;  // zero-length (or unplannable) move: stays at rest, duration 0
  }
  const double a = l.acceleration, j = l.jerk;
  // Ramp time to reach speed v (from rest): with or without an acceleration plateau.
  const auto ramp_time = [&](double v) { return v >= a * a / j ? v / a + a / j : 2.0 * std::sqrt(v / j); };
  double vp = l.velocity;
  double cruise = 0.0;
  if (vp * ramp_time(vp) <= d) {
    cruise = (d - vp * ramp_time(vp)) / vp;
  } else {
    // Ramp up and down meet: v·T(v) = d. Try the plateau case first, fall back to pure jerk phases.
    vp = 0.5 * a * (-a / j + std::sqrt(a * a / (j * j) + 4.0 * d / a));
    if (vp < a * a / j) vp = std::cbrt(d * d * j / 4.0);
  }
  const double tj = std::min(a / j, std::sqrt(vp / j));
  const double ap = j * tj;
  const double ta = std::max(0.0, vp / ap - tj);  // acceleration plateau
  const std::array<double, 7> dur{tj, ta, tj, cruise, tj, ta, tj};
  const std::array<double, 7> jerk{j, 0.0, -j, 0.0, -j, 0.0, j};
  double t = 0.0, p = 0.0, v = 0.0, acc = 0.0;
  for (std::size_t i = 0; i < 7; ++i) {
    m.seg_[i] = {t, jerk[i], p, v, acc};
    const double h = dur[i];
    p += v * h + acc * h * h / 2.0 + jerk[i] * h * h * h / 6.0;
    v += acc * h + jerk[i] * h * h / 2.0;
    acc += jerk[i] * h;
    t += h;
  }
  m.duration_ = t;
  m.peak_velocity_ = vp;
  m.ramp_time_ = 2.0 * tj + ta;
  m.ramp_distance_ = vp * m.ramp_time_ / 2.0;  // symmetric ramp: average speed vp/2
  return m;
}

MoveSample JerkMove::at(double t) const noexcept {
  if (t <= 0.0 || duration_ <= 0.0) return {t <= 0.0 ? 0.0 : distance_, 0.0, 0.0, 0.0};
  if (t >= duration_) return {distance_, 0.0, 0.0, 0.0};
  std::size_t i = 6;
  while (i > 0 && seg_[i].t0 > t) --i;
  const Segment& s = seg_[i];
  const double h = t - s.t0;
  MoveSample out;
  out.jerk = sign_ * s.jerk;
  out.acceleration = sign_ * (s.a0 + s.jerk * h);
  out.velocity = sign_ * (s.v0 + s.a0 * h + s.jerk * h * h / 2.0);
  out.position = sign_ * (s.p0 + s.v0 * h + s.a0 * h * h / 2.0 + s.jerk * h * h * h / 6.0);
  return out;
}

double JerkMove::position_at(double t) const noexcept {
  if (t <= 0.0 || duration_ <= 0.0) return t <= 0.0 ? 0.0 : distance_;
  if (t >= duration_) return distance_;
  std::size_t i = 6;
  while (i > 0 && seg_[i].t0 > t) --i;
  const Segment& s = seg_[i];
  const double h = t - s.t0;
  return sign_ * (s.p0 + s.v0 * h + s.a0 * h * h / 2.0 + s.jerk * h * h * h / 6.0);
}

}  // namespace loom::motion
