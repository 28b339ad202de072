// Angle helpers shared by every mechanism: wrapping without drift or NaN.
#include "loom/motion/angles.hpp"

#include <cmath>

namespace loom::motion {

double wrap_two_pi(double a) {
  double r = std::fmod(a, kTwoPi);
  if (r < 0.0) r += kTwoPi;
  // fmod of a value a hair below a multiple of 2π can round up to exactly 2π after the add.
  return r >= kTwoPi ? 0.0 : r;
}

double wrap_pi(double a) {
  double r = wrap_two_pi(a + kPi) - kPi;
  return r;
}

}  // namespace loom::motion
