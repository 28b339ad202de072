// The carriage cam: a staircase of smooth steps, one per crank turn, placed in the clear window.
#include "loom/motion/carriage_cam.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

CamSample smooth_step(double u) noexcept {
  if (!(u > 0.0)) return {0.0, 0.0, 0.0, 0.0};
  if (u >= 1.0) return {1.0, 0.0, 0.0, 0.0};
  const double u2 = u * u, u3 = u2 * u, u4 = u3 * u;
  CamSample s;
  s.position = u4 * (35.0 - 84.0 * u + 70.0 * u2 - 20.0 * u3);
  s.d1 = u3 * (140.0 - 420.0 * u + 420.0 * u2 - 140.0 * u3);
  s.d2 = u2 * (420.0 - 1680.0 * u + 2100.0 * u2 - 840.0 * u3);
  s.d3 = u * (840.0 - 5040.0 * u + 8400.0 * u2 - 4200.0 * u3);
  return s;
}

CarriageCam::CarriageCam(const WarpWindow& warp, double margin_rad, double pitch_m, int steps,
                         int beats_per_position)
    : pitch_(pitch_m), steps_(steps), beats_per_position_(beats_per_position) {
  start_ = warp.exit + margin_rad;
  length_ = warp.clear() - 2.0 * margin_rad;
  if (!(length_ > 0.0)) {
    std::ostringstream os;
    os << "carriage step window is empty: clear window " << deg(warp.clear()) << " deg minus 2 x margin "
       << deg(margin_rad) << " deg";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  if (beats_per_position < 1) {
    std::ostringstream os;
    os << "beats per carriage position must be >= 1, got " << beats_per_position;
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  if (!(pitch_m > 0.0) || steps < 0) {
    std::ostringstream os;
    os << "carriage pitch must be positive (got " << pitch_m << " m) and steps >= 0 (got " << steps << ")";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
}

CamSample CarriageCam::at(double phase) const noexcept {
  if (!(phase > start_) || steps_ == 0) return {};
  const double rel = phase - start_;
  // Window k follows turn k's beat; the carriage moves only in every beats_per_position-th window.
  const double k = std::floor(rel / kTwoPi);
  const double n = static_cast<double>(beats_per_position_);
  const double started = std::floor((k + 1.0) / n);  // moves whose window has begun
  const double total = static_cast<double>(steps_);
  if (started > total || (started == total && std::fmod(k + 1.0, n) != 0.0)) return {pitch_ * total, 0.0, 0.0, 0.0};
  if (std::fmod(k + 1.0, n) != 0.0) return {pitch_ * started, 0.0, 0.0, 0.0};  // dwelling between beats
  const double u = (rel - k * kTwoPi) / length_;
  const CamSample s = smooth_step(u);
  const double c = 1.0 / length_;
  return {pitch_ * (started - 1.0 + s.position), pitch_ * s.d1 * c, pitch_ * s.d2 * c * c, pitch_ * s.d3 * c * c * c};
}

}  // namespace loom::motion
