// SI ↔ counts conversion with explicit handling of non-finite and out-of-range values, so a bad
// target can never become undefined behaviour in a float→integer conversion on the RT path.
#include "loom/drivers/position_scaling.hpp"

#include <cmath>
#include <limits>

namespace loom::drivers {

std::int64_t si_to_counts(double si, double counts_per_unit) noexcept {
  const double c = std::round(si * counts_per_unit);
  if (!std::isfinite(c)) return 0;
  // ±2^62 is far beyond any mechanism and exactly representable as a double.
  constexpr double kLimit = 4611686018427387904.0;
  if (c >= kLimit) return static_cast<std::int64_t>(kLimit);
  if (c <= -kLimit) return -static_cast<std::int64_t>(kLimit);
  return static_cast<std::int64_t>(c);
}

double counts_to_si(std::int64_t counts, double counts_per_unit) noexcept {
  return static_cast<double>(counts) / counts_per_unit;
}

}  // namespace loom::drivers
