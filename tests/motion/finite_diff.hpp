// Finite-difference stencils used as independent truth for the mechanisms' analytic rates.
// Five-point central formulas: O(h⁴) truncation, so h ~ 1e-3 leaves both truncation and rounding
// far below the 1e-6 relative agreement the tests demand.
#pragma once

#include <algorithm>
#include <cmath>

namespace loom::test {

// f'(t) ≈ [f(t-2h) - 8f(t-h) + 8f(t+h) - f(t+2h)] / 12h
template <class F>
double d1(F&& f, double t, double h) {
  return (f(t - 2 * h) - 8 * f(t - h) + 8 * f(t + h) - f(t + 2 * h)) / (12 * h);
}

// f''(t) ≈ [-f(t-2h) + 16f(t-h) - 30f(t) + 16f(t+h) - f(t+2h)] / 12h²
template <class F>
double d2(F&& f, double t, double h) {
  return (-f(t - 2 * h) + 16 * f(t - h) - 30 * f(t) + 16 * f(t + h) - f(t + 2 * h)) / (12 * h * h);
}

// Relative agreement over a cycle: |a - b| measured against the largest magnitude the quantity
// reaches over the cycle, so zero crossings do not blow the ratio up.
inline bool close_rel(double analytic, double numeric, double cycle_scale, double rel) {
  return std::abs(analytic - numeric) <= rel * std::max(cycle_scale, 1e-300);
}

}  // namespace loom::test
