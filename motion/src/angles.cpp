// Angle helpers shared by every mechanism: wrapping without drift or NaN.
#include "loom/motion/angles.hpp"

#include <cmath>

namespace loom::motion {

namespace {
// fmod(a, 2π) without the libm call on the tick's path: fmod's result a − n·2π (n = trunc(a / 2π)) is
// exactly representable, so fma(−n, 2π, a), which rounds once, returns it exactly — when n is the right
// integer. The division may round n one off near a multiple; the remainder's sign or size shows it and
// one more fma corrects it. Beyond 2^40 (n no longer tiny against the mantissa) it is fmod itself.
double fmod_two_pi(double a) {
  if (!(std::abs(a) < 1099511627776.0)) return std::fmod(a, kTwoPi);  // also NaN and inf
  double n = std::trunc(a / kTwoPi);
  double r = std::fma(-n, kTwoPi, a);
  if (a >= 0.0 ? r < 0.0 : r > 0.0) {
    n += a >= 0.0 ? -1.0 : 1.0;
    r = std::fma(-n, kTwoPi, a);
  } else if (std::abs(r) >= kTwoPi) {
    n += a >= 0.0 ? 1.0 : -1.0;
    r = std::fma(-n, kTwoPi, a);
  }
  return r == 0.0 ? std::copysign(0.0, a)
                  : r;  // fmod's zero has the sign of a; fma's exact cancellation is +0
}
}  // namespace

double wrap_two_pi(double a) {
  double r = fmod_two_pi(a);
  if (r < 0.0) r += kTwoPi;
  // fmod of a value a hair below a multiple of 2π can round up to exactly 2π after the add.
  return r >= kTwoPi ? 0.0 : r;
}

double wrap_pi(double a) {
  double r = wrap_two_pi(a + kPi) - kPi;
  return r;
}

}  // namespace loom::motion
