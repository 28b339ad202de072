// Beat-up head kinematics. The warp window is found by bisection on the tip's arc distance from the
// fell, which is monotonic between the two dead centres, so each boundary is unique and bracketed.
#include "loom/motion/beatup.hpp"

#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

BeatUpGeometry default_beatup_geometry() {
  BeatUpGeometry g;
  g.bar = FourBar{.ground = 0.213, .crank = 0.058, .coupler = 0.189, .rocker = 0.232};
  return g;
}

BeatUp::BeatUp(const BeatUpGeometry& g) : g_(g), dc_(motion::dead_centres(g.bar, g.branch)) {
  if (!(g.beater_arm_m > 0.0) || !std::isfinite(g.beater_arm_m)) {
    std::ostringstream os;
    os << "beater arm must be positive, got " << g.beater_arm_m << " m";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  const bool ext = g.fell_at == FellSide::kExtended;
  fell_theta2_ = ext ? dc_.crank_extended : dc_.crank_folded;
  fell_theta4_ = ext ? dc_.rocker_extended : dc_.rocker_folded;
  const double stroke = stroke_arc_m();
  if (!(g.warp_depth_m > 0.0) || !(g.warp_depth_m < stroke)) {
    std::ostringstream os;
    os << "warp depth " << g.warp_depth_m << " m must lie inside the beater stroke (0, " << stroke << ") m";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  // The crank turns CCW. Before the fell it comes from the other dead centre; after, it goes toward it.
  const double other_theta2 = ext ? dc_.crank_folded : dc_.crank_extended;
  const double before = wrap_two_pi(fell_theta2_ - other_theta2);  // crank travel other → fell
  const double after = kTwoPi - before;                            // crank travel fell → other
  const auto depth_at = [&](double theta2) { return from_fell(solve(g_.bar, theta2, g_.branch).theta4); };
  // Bisection: find offset x in (0, span) with depth(fell ± x) = warp depth; depth grows with x.
  const auto boundary = [&](double dir, double span) {
    double lo = 0.0, hi = span;
    for (int i = 0; i < 80 && hi - lo > 1e-15; ++i) {
      const double mid = 0.5 * (lo + hi);
      (depth_at(fell_theta2_ + dir * mid) < g_.warp_depth_m ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  const double in_offset = boundary(-1.0, before);
  const double out_offset = boundary(+1.0, after);
  // Park in the middle of the clear window, opposite the warp.
  const double clear = kTwoPi - in_offset - out_offset;
  park_theta2_ = wrap_two_pi(fell_theta2_ + out_offset + 0.5 * clear);
  warp_.fell = wrap_two_pi(fell_theta2_ - park_theta2_);
  warp_.enter = warp_.fell - in_offset;
  warp_.exit = warp_.fell + out_offset;
}

double BeatUp::from_fell(double theta4) const {
  return g_.beater_arm_m * std::abs(wrap_pi(theta4 - fell_theta4_));
}

BeaterState BeatUp::at(double phase) const {
  const FourBarPose p = solve(g_.bar, park_theta2_ + phase, g_.branch);
  BeaterState s;
  // Continuous through a turn: measured from the fell pose, which the rocker never swings π away from.
  s.rocker_angle = fell_theta4_ + wrap_pi(p.theta4 - fell_theta4_);
  s.d1 = p.k4;
  s.d2 = p.k4p;
  s.from_fell_m = from_fell(p.theta4);
  s.in_warp = s.from_fell_m < g_.warp_depth_m;
  return s;
}

}  // namespace loom::motion
