// Carriage step peaks by the chain rule through the crank law: with x(Φc) the cam and Φc(Φm) the law
// at constant master speed ω, v = x'Φ̇c, a = x''Φ̇c² + x'Φ̈c, j = x'''Φ̇c³ + 3x''Φ̇cΦ̈c + x'Φ⃛c, where
// Φ̇c = ωΦc', Φ̈c = ω²Φc'', Φ⃛c = ω³Φc'''. Each peak scales with ω, ω² and ω³, which gives the fastest
// feasible crank speed in closed form.
#include "loom/motion/profile_carriage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

constexpr int kSamplesPerTurn = 4096;

// Master phase at which the crank reaches `crank` (the law is increasing; bracket by ±π around it,
// since the offset stays within a quarter turn for any e < 1 and k >= 2, within π for k = 1).
double master_at(const CrankLaw& law, double crank) {
  double lo = crank - kTwoPi, hi = crank + kTwoPi;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (mid + law.exact(mid).offset < crank ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

CarriagePeaks carriage_step_peaks(const CarriageCam& cam, const CrankLaw& law, double omega,
                                  const CarriageLimits& limits) {
  CarriagePeaks peaks;
  peaks.max_crank_speed_rad_s = std::numeric_limits<double>::infinity();
  if (cam.steps() == 0) return peaks;  // one beat per row: the carriage never moves
  const double start = cam.window_start(), length = cam.window_length(), pitch = cam.pitch();

  std::vector<double> masters;
  masters.reserve(kSamplesPerTurn + 5);
  const double m0 = master_at(law, start);
  for (int j = 0; j <= kSamplesPerTurn; ++j) masters.push_back(m0 + kTwoPi * j / kSamplesPerTurn);
  if (law.spec().kind == CrankLawKind::kConstant) {
    // Where s', s'' and s''' of the smooth step peak: u = 1/2, (5 ± √5)/10, (5 ± √15)/10.
    for (double u : {0.5, (5.0 - std::sqrt(5.0)) / 10.0, (5.0 + std::sqrt(5.0)) / 10.0,
                     (5.0 - std::sqrt(15.0)) / 10.0, (5.0 + std::sqrt(15.0)) / 10.0}) {
      masters.push_back(start + u * length);
    }
  }
  for (double m : masters) {
    const CrankLawExact c = law.exact(m);
    const double rel = wrap_two_pi(m + c.offset - start);
    if (!(rel < length)) continue;  // dwelling: the beater is in (or near) the warp
    const CamSample s = smooth_step(rel / length);
    const double x1 = pitch * s.d1 / length;
    const double x2 = pitch * s.d2 / (length * length);
    const double x3 = pitch * s.d3 / (length * length * length);
    const double w1 = omega * c.d1, w2 = omega * omega * c.d2, w3 = omega * omega * omega * c.d3;
    peaks.speed_m_s = std::max(peaks.speed_m_s, std::abs(x1 * w1));
    peaks.accel_m_s2 = std::max(peaks.accel_m_s2, std::abs(x2 * w1 * w1 + x1 * w2));
    peaks.jerk_m_s3 = std::max(peaks.jerk_m_s3, std::abs(x3 * w1 * w1 * w1 + 3.0 * x2 * w1 * w2 + x1 * w3));
  }
  peaks.step_time_s = (master_at(law, start + length) - m0) / omega;
  const auto headroom = [](double limit, double need, double power) {
    return need > 0.0 ? std::pow(limit / need, 1.0 / power) : std::numeric_limits<double>::infinity();
  };
  peaks.max_crank_speed_rad_s = omega * std::min({headroom(limits.speed_m_s, peaks.speed_m_s, 1.0),
                                                  headroom(limits.accel_m_s2, peaks.accel_m_s2, 2.0),
                                                  headroom(limits.jerk_m_s3, peaks.jerk_m_s3, 3.0)});
  return peaks;
}

CarriagePeaks check_carriage_step(const CarriageCam& cam, const CrankLaw& law, double omega,
                                  const CarriageLimits& limits) {
  for (const auto& [name, v] : {std::pair{"carriage.max_speed_m_s", limits.speed_m_s},
                                std::pair{"carriage.max_accel_m_s2", limits.accel_m_s2},
                                std::pair{"carriage.max_jerk_m_s3", limits.jerk_m_s3}}) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      std::ostringstream os;
      os << name << " = " << v << ": carriage limits must be positive and finite";
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
  }
  const CarriagePeaks p = carriage_step_peaks(cam, law, omega, limits);
  const bool v = p.speed_m_s > limits.speed_m_s, a = p.accel_m_s2 > limits.accel_m_s2,
             j = p.jerk_m_s3 > limits.jerk_m_s3;
  if (!v && !a && !j) return p;
  std::ostringstream os;
  os << "carriage step of " << cam.pitch() * 1e3
     << " mm does not fit the beater's clear window at crank speed " << omega << " rad/s ("
     << crank_law_name(law.spec().kind) << " law): the window leaves " << deg(cam.window_length())
     << " deg of crank (" << p.step_time_s * 1e3 << " ms) after the cam margins, and the step needs peak "
     << p.speed_m_s << " m/s, " << p.accel_m_s2 << " m/s^2, " << p.jerk_m_s3
     << " m/s^3; the limits are carriage.max_speed_m_s = " << limits.speed_m_s << (v ? " (exceeded)" : "")
     << ", carriage.max_accel_m_s2 = " << limits.accel_m_s2 << (a ? " (exceeded)" : "")
     << ", carriage.max_jerk_m_s3 = " << limits.jerk_m_s3 << (j ? " (exceeded)" : "")
     << ". Lower recipe.crank_speed_rad_s to at most " << p.max_crank_speed_rad_s
     << " rad/s, or shorten the pitch (beatup.beater_width_m, recipe.overlap_m), or lower "
        "recipe.cam_margin_deg";
  throw MotionError(ErrorCode::kInvalidInput, os.str());
}

}  // namespace loom::motion
