// Deterministic, allocation-free random numbers for the simulator's noise and probability effects.
#pragma once

#include <cstdint>

namespace loom::sim_hal {

// splitmix64: a scene's seed replays a run exactly.
class SimRandom {
 public:
  explicit SimRandom(std::uint64_t seed) : state_(seed) {}
  double uniform() noexcept;  // [0, 1)

 private:
  std::uint64_t state_;
};

}  // namespace loom::sim_hal
