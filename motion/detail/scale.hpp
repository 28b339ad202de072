// Scale-free solving: a linkage is solved in units of a power of two near its largest length, so
// squares and products of lengths can neither overflow nor underflow at any scale a double holds
// (1e-150 … 1e150 and beyond), and — a power of two being exact — results at ordinary scales are
// bit-identical to solving in the given units.
#pragma once

#include <cmath>

namespace loom::motion::detail {

// RT-safe. 2^floor(log2(largest)) for a finite largest > 0.
inline double length_scale(double largest) {
  return std::ldexp(1.0, std::ilogb(largest));
}

}  // namespace loom::motion::detail
