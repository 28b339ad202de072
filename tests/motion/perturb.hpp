// Deterministic scale factors for the "perturbed designs" property tests: a linear congruential
// generator, so every run (and every platform) draws the same family of designs.
#pragma once

namespace loom::test {

class Perturbation {
 public:
  // Factors uniform in [lo, hi) from `seed`.
  Perturbation(unsigned seed, double lo, double hi) : seed_(seed), lo_(lo), span_(hi - lo) {}
  double next() {
    seed_ = seed_ * 1664525u + 1013904223u;
    return lo_ + span_ * (static_cast<double>(seed_ >> 8) / static_cast<double>(1u << 24));
  }

 private:
  unsigned seed_;
  double lo_, span_;
};

}  // namespace loom::test
