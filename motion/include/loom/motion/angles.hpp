// Angle constants and wrapping helpers (rad). Pure functions, RT-safe.
#pragma once

#include <numbers>

namespace loom::motion {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;
inline constexpr double deg(double rad) {
  return rad * 180.0 / kPi;
}
inline constexpr double rad(double deg) {
  return deg * kPi / 180.0;
}

// RT-safe. Wrap to [0, 2π).
double wrap_two_pi(double a);
// RT-safe. Wrap to [-π, π).
double wrap_pi(double a);

}  // namespace loom::motion
