// The carriage cam: a staircase of smooth steps, one per crank turn, placed in the clear window.
#include "loom/motion/carriage_cam.hpp"

#include <cmath>
#include <cstdint>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

static double smooth_step_position(double u) noexcept {  // smooth_step(u).position alone
  if (!(u > 0.0)) return 0.0;
  if (u >= 1.0) return 1.0;
  const double u2 = u * u, u3 = u2 * u, u4 = u3 * u;
  return u4 * (35.0 - 84.0 * u + 70.0 * u2 - 20.0 * u3);
}

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

namespace {
// floor(x) for x >= 0 (or NaN), bit for bit, without libm's call on the tick's path: below 2^63 the
// truncating conversion is the floor; at and above 2^52 every double is whole already.
double floor_nonneg(double x) noexcept {
  return x < 0x1p52 ? static_cast<double>(static_cast<std::int64_t>(x)) : std::floor(x);
}
// fmod(m, n) != 0 for a whole m >= 1 and n >= 1: whether m is not a multiple of n, in integers (exact,
// as fmod is) while m fits them.
bool not_multiple(double m, int n) noexcept {
  if (n == 1) return false;
  if (m < 0x1p63) return static_cast<std::uint64_t>(m) % static_cast<std::uint64_t>(n) != 0;
  return std::fmod(m, static_cast<double>(n)) != 0.0;
}
}  // namespace

CamSample CarriageCam::at(double phase) const noexcept {
  if (!(phase > start_) || steps_ == 0) return {};
  const double rel = phase - start_;
  // Window k follows turn k's beat; the carriage moves only in every beats_per_position-th window.
  const double k = floor_nonneg(rel / kTwoPi);  // rel > 0
  const double n = static_cast<double>(beats_per_position_);
  const double started = floor_nonneg((k + 1.0) / n);  // moves whose window has begun
  const double total = static_cast<double>(steps_);
  if (started > total) return {pitch_ * total, 0.0, 0.0, 0.0};
  // (from here started <= total: k is finite)
  const bool between = not_multiple(k + 1.0, beats_per_position_);
  if (started == total && between) return {pitch_ * total, 0.0, 0.0, 0.0};
  if (between) return {pitch_ * started, 0.0, 0.0, 0.0};  // dwelling between beats
  const double u = (rel - k * kTwoPi) / length_;
  const CamSample s = smooth_step(u);
  const double c = 1.0 / length_;
  return {pitch_ * (started - 1.0 + s.position), pitch_ * s.d1 * c, pitch_ * s.d2 * c * c,
          pitch_ * s.d3 * c * c * c};
}

double CarriageCam::position_at(double phase) const noexcept {
  if (!(phase > start_) || steps_ == 0) return 0.0;
  const double rel = phase - start_;
  // Window k follows turn k's beat; the carriage moves only in every beats_per_position-th window.
  const double k = floor_nonneg(rel / kTwoPi);  // rel > 0
  const double n = static_cast<double>(beats_per_position_);
  const double started = floor_nonneg((k + 1.0) / n);  // moves whose window has begun
  const double total = static_cast<double>(steps_);
  if (started > total) return pitch_ * total;
  // (from here started <= total: k is finite)
  const bool between = not_multiple(k + 1.0, beats_per_position_);
  if (started == total && between) return pitch_ * total;
  if (between) return pitch_ * started;  // dwelling between beats
  const double u = (rel - k * kTwoPi) / length_;
  return pitch_ * (started - 1.0 + smooth_step_position(u));
}

}  // namespace loom::motion
