// The warp's tension as the beat meets it (scene effect "warp_tension", with "beat_contact"): a real warp
// is not equally tight across the width (threads beamed unevenly, the selvedges held harder than the
// middle), it drifts as the carpet grows and the warp beam empties, and no two beats meet quite the same
// warp. A tauter warp holds the fell firmer, so the load cell sees the beat contact's force scaled by the
// warp's relative tension where the comb beats (1 = the uniform warp the loom was set up for).
// Built only when a scene names the effect; its work is per beat (at the first tick of each contact), none
// per tick.
#pragma once

#include <cstdint>

#include "loom/sim_hal/random.hpp"
#include "loom/sim_hal/scene.hpp"

namespace loom::sim_hal {

class WarpTensionModel {
 public:
  // Configure-time. `travel_m` = width − beater width (the carriage's travel in one row's sweep).
  WarpTensionModel(const WarpTension& p, const SimMachine& machine, std::uint64_t seed);

  // Relative tension across the width at u = 0 (left selvedge) … 1 (right selvedge), without drift or noise.
  double profile(double u) const noexcept;

  // RT-safe. The factor for the beat in contact now: `turn` counts crank turns (a new turn is a new beat,
  // which draws its own variation and counts the carriage travel since the last beat towards the rows
  // woven); `carriage_reading` is the carriage axis' reading. Constant for the rest of that contact.
  double factor(std::int64_t turn, double carriage_reading) noexcept;

  // Ground truth for tests: the rows the model has counted and the last beat's factor.
  double rows_woven() const noexcept { return rows_; }
  double last_factor() const noexcept { return factor_; }

 private:
  double gaussian() noexcept;  // standard normal (Box–Muller on the effect's own stream)

  WarpTension p_;
  double width_m_, beater_width_m_, home_m_, travel_m_;
  SimRandom rng_;
  std::int64_t turn_ = INT64_MIN;  // the crank turn of the last beat
  double last_x_ = 0.0;
  bool seen_beat_ = false;
  double rows_ = 0.0;
  double factor_ = 1.0;
};

}  // namespace loom::sim_hal
