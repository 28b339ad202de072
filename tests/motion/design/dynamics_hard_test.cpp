// Hard cases of the design library's dynamics (issue 13): seed 004's gain per visit of the double
// swing against the gear's closed form, and a shaking load that overflows refused with a typed error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/balancing.hpp"
#include "loom/motion/design/dynamics_batten.hpp"
#include "loom/motion/errors.hpp"

using namespace loom::motion;

// Issue 13, seed 004 per visit: the double swing visits each extreme twice per crank turn, always at
// the same two crank angles (dψ/dθ2 = 0 does not depend on the crank's speed law), and each visit's
// gain is exactly the gear's (dφ2/dφ1)² at the driving angle of that visit — checked here against the
// gear's own closed form, independent of the turning-point search.
TEST(BattenDynamics, EachVisitHasTheSquaredSpeedRatioOfItsOwnInstant) {
  const BattenLinkage l(batten_004_dims());
  const EllipticGearPair gear(kBatten004GearA_m, 0.2, 2);
  const BattenGain ref = batten_gain(l, gear, 0.0, BattenBeatSide::kPsiMin);
  ASSERT_EQ(ref.visits.size(), 2u);
  for (const double phi02 : {0.0, 0.9, 2.2, 3.0299, 5.5}) {
    const BattenGain g = batten_gain(l, gear, phi02, BattenBeatSide::kPsiMin);
    ASSERT_EQ(g.visits.size(), 2u) << phi02;
    double largest = 0.0;
    for (std::size_t i = 0; i < 2; ++i) {
      const BattenVisit& v = g.visits[i];
      EXPECT_NEAR(v.crank_rad, ref.visits[i].crank_rad, 1e-7) << phi02;  // fixed by the linkage
      const double ratio = gear.phase(v.phi1_rad).dphi2;
      EXPECT_NEAR(v.gain, ratio * ratio, 1e-6 * ratio * ratio) << phi02 << " visit " << i;
      largest = std::max(largest, v.accel_rad_s2);
    }
    EXPECT_NEAR(g.accel_rad_s2, largest, 1e-12 * largest);
    // The beat is the visit that is harder with the circular gear, whatever φ02 does to the gains.
    EXPECT_EQ(g.beat_visit, ref.beat_visit) << phi02;
    const BattenVisit& beat = g.visits[static_cast<std::size_t>(g.beat_visit)];
    const BattenVisit& other = g.visits[static_cast<std::size_t>(1 - g.beat_visit)];
    EXPECT_GE(beat.circular_accel_rad_s2, other.circular_accel_rad_s2);
  }
  // At the best orientation both ψ-min visits gain nearly the bound: they are 183.6° of crank apart
  // and a two-lobe gear repeats every 180°.
  const BattenSearch best = batten_best_phi02(l, gear, BattenBeatSide::kPsiMin, 1.0, 90);
  ASSERT_EQ(best.best.visits.size(), 2u);
  EXPECT_NEAR(best.best.visits[static_cast<std::size_t>(best.best.beat_visit)].gain, 2.25, 1e-7);
  EXPECT_GT(best.best.visits[static_cast<std::size_t>(1 - best.best.beat_visit)].gain, 2.2);
}

// Issue 13: a crank speed whose shaking load overflows is refused (it segfaulted on an empty result).
TEST(BalancingHard, OverflowingShakingLoadIsATypedError) {
  const loom::motion::BeatUpGeometry g = loom::motion::default_beatup_geometry();
  const loom::motion::BeatUpDynamics d(g, loom::motion::beatup_masses(g));
  const loom::motion::LinkageMotionSamples s = loom::motion::beatup_balancing_samples(d, 1e100, 12);
  for (int method = 0; method < 2; ++method) {
    try {
      if (method == 0) {
        loom::motion::balance_with_counterweights(s, {});
      } else {
        loom::motion::balance_by_redistribution(s, {});
      }
      ADD_FAILURE() << "expected a MotionError for method " << method;
    } catch (const loom::motion::MotionError& e) {
      EXPECT_EQ(e.code(), loom::motion::ErrorCode::kInvalidInput) << e.what();
      EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
    }
  }
}
