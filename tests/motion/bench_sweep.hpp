// The input angles the closed-form vs Newton benchmarks sweep: one turn in equal steps, so Newton's
// warm start is always the previous sample (0.1° away at 3600 samples).
#pragma once

#include <vector>

#include "loom/motion/angles.hpp"

namespace loom::test {

inline std::vector<double> sweep_angles(int samples) {
  std::vector<double> c(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) c[static_cast<std::size_t>(i)] = motion::kTwoPi * i / samples;
  return c;
}

}  // namespace loom::test
