// Jerk-limited rest-to-rest point-to-point move (seven-segment S-curve). Used for the helix-shaft pick
// and for the crank's run-up and run-down. Planning and evaluation are O(1), allocation-free and never
// throw, so the sequencer may plan a move inside a tick; limits are validated once at configure time.
#pragma once

#include <array>

namespace loom::motion {

struct JerkLimits {
  double velocity = 0.0;      // > 0, SI per s
  double acceleration = 0.0;  // > 0, SI per s²
  double jerk = 0.0;          // > 0, SI per s³
};

// Configure-time only: throws MotionError(kInvalidInput) naming the limit that is not positive/finite.
void validate(const JerkLimits& limits, const char* what);

struct MoveSample {
  double position = 0.0, velocity = 0.0, acceleration = 0.0, jerk = 0.0;
};

class JerkMove {
 public:
  JerkMove() = default;
  // RT-safe. A move of `distance` (signed, SI) from rest to rest within `limits` (validated beforehand).
  // The peak velocity is lowered when the distance is too short to reach it.
  static JerkMove plan(double distance, const JerkLimits& limits) noexcept;

  // RT-safe. Offset from the start position at time t (s) after the move began; clamped outside
  // [0, duration] (before: at rest at 0, after: at rest at `distance` exactly).
  MoveSample at(double t) const noexcept;
  // RT-safe. at(t).position alone (the same arithmetic, so the same bits), for a loop that needs no more.
  double position_at(double t) const noexcept;

  double duration() const noexcept { return duration_; }
  double distance() const noexcept { return distance_; }
  double peak_velocity() const noexcept { return sign_ * peak_velocity_; }
  // Distance covered (unsigned) until cruise speed is reached; equal to the braking distance.
  double ramp_distance() const noexcept { return ramp_distance_; }
  double ramp_time() const noexcept { return ramp_time_; }

 private:
  struct Segment {
    double t0 = 0.0, jerk = 0.0, p0 = 0.0, v0 = 0.0, a0 = 0.0;
  };
  std::array<Segment, 7> seg_{};
  double duration_ = 0.0;
  double distance_ = 0.0;
  double sign_ = 1.0;
  double peak_velocity_ = 0.0;
  double ramp_distance_ = 0.0;
  double ramp_time_ = 0.0;
};

}  // namespace loom::motion
