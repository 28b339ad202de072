// Fixed-point phase: conversions at the boundary to real numbers, and the exact n-fold step that
// tests and jumps use. The 64×64→128-bit product is the one place a wider integer is needed.
#include <cmath>
#include <numbers>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/phase.hpp"

namespace loom::motion {

namespace {
__extension__ using Wide = unsigned __int128;
constexpr double kSaturateTurns = 4611686018427387904.0;  // 2^62
}  // namespace

Phase Phase::times(std::int64_t n) const noexcept {
  const bool negative = n < 0;
  const std::uint64_t m =
      negative ? std::uint64_t{0} - static_cast<std::uint64_t>(n) : static_cast<std::uint64_t>(n);
  const Wide product = static_cast<Wide>(frac) * m;
  Phase r;
  r.frac = static_cast<std::uint64_t>(product);
  // Whole turns wrap like int64 (documented): do the arithmetic unsigned, where wrapping is defined.
  r.turns = static_cast<std::int64_t>(static_cast<std::uint64_t>(turns) * m +
                                      static_cast<std::uint64_t>(product >> 64));
  return negative ? -r : r;
}

Phase Phase::from_turns(double x) noexcept {
  if (!std::isfinite(x)) return {};
  // The clamp, floor and round-to-nearest below are fmax/fmin, floor and nearbyint bit for bit (for
  // finite x; the whole turns and units they produce are the same), without libm calls on the tick's
  // path (x86-64 without SSE4.1 has no rounding instruction).
  x = x < -kSaturateTurns ? -kSaturateTurns : x > kSaturateTurns ? kSaturateTurns : x;
  double whole = static_cast<double>(static_cast<std::int64_t>(x));  // |x| <= 2^62: truncation is exact
  if (whole > x) whole -= 1.0;                                       // floor for negative x
  double rest = x - whole;                     // exact for |x| < 2^62; in [0, 1] after rounding
  const double scaled = rest * kUnitsPerTurn;  // >= 0
  // Adding and taking away 2^52 rounds a value below 2^52 to a whole number in the current rounding mode,
  // as nearbyint does; from 2^52 up every double is whole.
  double units = scaled < 0x1p52 ? (scaled + 0x1p52) - 0x1p52 : scaled;
  if (units >= kUnitsPerTurn) {  // rounds up to a whole turn
    whole += 1.0;
    units = 0.0;
  }
  return {static_cast<std::int64_t>(whole), static_cast<std::uint64_t>(units)};
}

Phase Phase::from_rad(double rad) noexcept {
  return from_turns(rad / kTwoPi);
}

double Phase::to_turns() const noexcept {
  return static_cast<double>(turns) + frac_turns();
}

double Phase::to_rad() const noexcept {
  return kTwoPi * static_cast<double>(turns) + frac_rad();
}

double Phase::frac_rad() const noexcept {
  return kTwoPi * frac_turns();
}

Phase phase_step(double speed_rad_s, double period_s) {
  if (!std::isfinite(speed_rad_s) || !(period_s > 0.0) || !std::isfinite(period_s)) {
    std::ostringstream os;
    os << "phase step: speed " << speed_rad_s << " rad/s and period " << period_s
       << " s must be finite, the period positive";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  // In long double so the step is the nearest fixed-point value to the exact product, not to its
  // double rounding (which alone would be ~10 units, 1e-16 relative, per tick).
  const long double turns = static_cast<long double>(speed_rad_s) * static_cast<long double>(period_s) /
                            (2.0L * std::numbers::pi_v<long double>);
  if (std::fabs(turns) >= 0x1p62L) return Phase::from_turns(static_cast<double>(turns));
  long double whole = std::floor(turns);
  long double units = std::nearbyint((turns - whole) * 0x1p64L);
  if (units >= 0x1p64L) {
    whole += 1.0L;
    units = 0.0L;
  }
  return {static_cast<std::int64_t>(whole), static_cast<std::uint64_t>(units)};
}

}  // namespace loom::motion
