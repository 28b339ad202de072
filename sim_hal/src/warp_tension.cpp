// The warp's tension at each beat (see warp_tension.hpp).
#include "loom/sim_hal/warp_tension.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace loom::sim_hal {

WarpTensionModel::WarpTensionModel(const WarpTension& p, const SimMachine& m, std::uint64_t seed)
    : p_(p),
      width_m_(m.width_m),
      beater_width_m_(m.beater_width_m),
      home_m_(m.carriage_home_m),
      travel_m_(m.width_m - m.beater_width_m),
      // Its own stream: naming the effect does not change what any other effect draws from the scene's seed.
      rng_(seed ^ 0x7E45105EC0FFEEull) {
  if (!(travel_m_ > 0.0))
    throw std::invalid_argument("effect 'warp_tension': the beater is as wide as the loom");
  if (p_.points.size() == 1)
    throw std::invalid_argument("effect 'warp_tension': points needs at least two values");
}

double WarpTensionModel::profile(double u) const noexcept {
  u = std::clamp(u, 0.0, 1.0);
  if (p_.points.empty()) return 1.0 + (p_.centre_ratio - 1.0) * 4.0 * u * (1.0 - u);  // 1 at both selvedges
  const double at = u * static_cast<double>(p_.points.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(at), p_.points.size() - 2);
  const double f = at - static_cast<double>(i);
  return p_.points[i] + f * (p_.points[i + 1] - p_.points[i]);
}

double WarpTensionModel::gaussian() noexcept {
  // Box–Muller: u1 in (0, 1] so the log is finite.
  const double u1 = 1.0 - rng_.uniform();
  const double u2 = rng_.uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

double WarpTensionModel::factor(std::int64_t turn, double carriage_reading) noexcept {
  if (turn == turn_) return factor_;
  turn_ = turn;
  const double x = carriage_reading - home_m_;  // the comb's left edge from the left selvedge
  // The carpet grows by a row per sweep of the carriage across its travel: count the travel between beats.
  if (seen_beat_) rows_ += std::abs(x - last_x_) / travel_m_;
  seen_beat_ = true;
  last_x_ = x;
  const double u = (x + 0.5 * beater_width_m_) / width_m_;  // the comb's middle across the width
  const double drift = std::max(0.0, 1.0 + p_.drift_per_row * rows_);
  const double variation = p_.noise > 0.0 ? std::max(0.0, 1.0 + p_.noise * gaussian()) : 1.0;
  factor_ = profile(u) * drift * variation;
  return factor_;
}

}  // namespace loom::sim_hal
