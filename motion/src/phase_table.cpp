// Cubic Hermite on uniformly spaced phase samples. Storing the exact slope (not finite differences)
// gives O(h⁴) position error at no extra lookup cost.
#include "loom/motion/phase_table.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

PhaseTable::PhaseTable(std::size_t n, const std::function<Exact(double)>& f) {
  if (n < 4) {
    std::ostringstream os;
    os << "phase table needs at least 4 samples, got " << n;
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  value_.resize(n);
  slope_.resize(n);
  step_ = kTwoPi / static_cast<double>(n);
  inv_step_ = 1.0 / step_;
  for (std::size_t i = 0; i < n; ++i) {
    const Exact e = f(step_ * static_cast<double>(i));
    if (!std::isfinite(e.value) || !std::isfinite(e.d1)) {
      std::ostringstream os;
      os << "phase table sample " << i << " is not finite";
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
    value_[i] = e.value;
    slope_[i] = e.d1;
  }
}

PhaseSample PhaseTable::at(double phase) const noexcept {
  const double p = std::isfinite(phase) ? wrap_two_pi(phase) : 0.0;
  const double x = p * inv_step_;
  std::size_t i = static_cast<std::size_t>(x);
  const std::size_t n = value_.size();
  if (i >= n) i = n - 1;  // p just below 2π can round to n
  const std::size_t k = (i + 1 == n) ? 0 : i + 1;
  const double t = x - static_cast<double>(i);
  const double h = step_;
  const double y0 = value_[i];
  const double y1 = value_[k];  // the function is periodic: the sample after the last is the first
  const double m0 = slope_[i] * h, m1 = slope_[k] * h;
  const double t2 = t * t, t3 = t2 * t;
  PhaseSample s;
  s.value = (2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * y1 + (t3 - t2) * m1;
  s.d1 = ((6 * t2 - 6 * t) * y0 + (3 * t2 - 4 * t + 1) * m0 + (-6 * t2 + 6 * t) * y1 + (3 * t2 - 2 * t) * m1) *
         inv_step_;
  s.d2 = ((12 * t - 6) * y0 + (6 * t - 4) * m0 + (-12 * t + 6) * y1 + (6 * t - 2) * m1) * inv_step_ * inv_step_;
  return s;
}

}  // namespace loom::motion
