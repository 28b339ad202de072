// Electronic cam of the carriage on the beat-up crank: during a beat sweep the carriage dwells while
// the beater is in the warp and steps one pitch (beater width minus overlap) inside each clear window,
// with a smooth step whose velocity, acceleration and jerk vanish at both ends. Input is the crank's
// unwrapped phase since the sweep began (0 = park); output is carriage travel from the sweep's start.
#pragma once

#include "loom/motion/beatup.hpp"

namespace loom::motion {

struct CamSample {
  double position = 0.0;  // m from the sweep's start position (≥ 0; direction applied by the caller)
  double d1 = 0.0;        // dx/dΦ (m/rad)
  double d2 = 0.0;        // d²x/dΦ² (m/rad²)
  double d3 = 0.0;        // d³x/dΦ³ (m/rad³)
};

class CarriageCam {
 public:
  CarriageCam() = default;
  // Configure-time. `pitch_m` per step, `steps` steps (positions - 1), moving in the window
  // [warp.exit + margin, warp.enter + 2π - margin] after every `beats_per_position`-th turn, so each
  // position is beaten that many times. Throws MotionError(kInvalidInput) when the margins leave no
  // window, the pitch is not positive or beats_per_position < 1.
  CarriageCam(const WarpWindow& warp, double margin_rad, double pitch_m, int steps,
              int beats_per_position = 1);

  // RT-safe. Φ = unwrapped crank phase since the sweep began.
  CamSample at(double crank_phase) const noexcept;
  // RT-safe. at(crank_phase).position alone (the same arithmetic, so the same bits).
  double position_at(double crank_phase) const noexcept;

  double window_start() const { return start_; }  // phase of the first step's start
  double window_length() const { return length_; }
  double pitch() const { return pitch_; }
  int steps() const { return steps_; }
  int beats_per_position() const { return beats_per_position_; }

 private:
  double start_ = 0.0;
  double length_ = 1.0;
  double pitch_ = 0.0;
  int steps_ = 0;
  int beats_per_position_ = 1;
};

// The smooth step s(u) = 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷ on [0,1] and its derivatives: s, s', s'', s''' all
// continuous, with s', s'', s''' zero at both ends, so chained steps are jerk-continuous.
CamSample smooth_step(double u) noexcept;

}  // namespace loom::motion
