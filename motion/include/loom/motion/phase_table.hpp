// A periodic function of crank phase sampled once at configure time (value and first derivative per
// sample) and read back in O(1) by cubic Hermite interpolation. The skeleton's profile table; the
// profiles issue adds more orders and fixed-point phase.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace loom::motion {

struct PhaseSample {
  double value = 0.0;
  double d1 = 0.0;  // d value / d phase
  double d2 = 0.0;  // d² value / d phase² (from the interpolant; piecewise linear for cubic Hermite)
};

class PhaseTable {
 public:
  // Configure-time only. Samples f at n points (n >= 4) over one turn [0, 2π); f(φ) returns the exact
  // value and slope and must be periodic over the turn (f(2π) = f(0)). Throws MotionError(kInvalidInput) for n < 4 or non-finite samples.
  struct Exact {
    double value = 0.0;
    double d1 = 0.0;
  };
  PhaseTable(std::size_t n, const std::function<Exact(double)>& f);

  // RT-safe. Any finite phase (wrapped internally); a non-finite phase returns the sample at 0 rather
  // than propagating NaN into a setpoint.
  PhaseSample at(double phase) const noexcept;

  std::size_t size() const noexcept { return value_.size(); }
  std::size_t bytes() const noexcept { return 2 * value_.size() * sizeof(double); }

 private:
  std::vector<double> value_;
  std::vector<double> slope_;
  double step_ = 0.0;
  double inv_step_ = 0.0;
};

}  // namespace loom::motion
