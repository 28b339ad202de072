// Elliptic-gear batten (004) at the beat. At a turning point ψ' = 0, so ψ'' = (d²ψ/dφ2²)(dφ2/dφ1)²ω1²:
// the best the gear can do is to put its fastest ratio, (1+e)/(1−e), on the beat — a gain of exactly
// ((1+e)/(1−e))², reached with the beat at the driving angle of the fastest ratio (cos kφ1 = −1).
#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/dynamics_batten.hpp"

using namespace loom::motion;

TEST(BattenDynamics, CircularGearHasUnitGainAtAnyOrientation) {
  const BattenLinkage l(batten_004_dims());
  const EllipticGearPair circular(kBatten004GearA_m, 0.0, 2);
  for (const double phi02 : {0.0, 0.7, 2.0, 4.5}) {
    EXPECT_NEAR(batten_gain(l, circular, phi02, BattenBeatSide::kPsiMin).gain, 1.0, 1e-9) << phi02;
  }
}

TEST(BattenDynamics, BestOrientationReachesTheSquaredSpeedRatio) {
  const BattenLinkage l(batten_004_dims());
  for (const double e : {0.1, 0.2, 0.3}) {
    for (const BattenBeatSide side : {BattenBeatSide::kPsiMax, BattenBeatSide::kPsiMin}) {
      const EllipticGearPair gear(kBatten004GearA_m, e, 2);
      const BattenSearch s = batten_best_phi02(l, gear, side, 1.0, 90);
      const double bound = std::pow((1.0 + e) / (1.0 - e), 2);
      EXPECT_NEAR(s.best.gain, bound, 1e-8 * bound) << e;
      for (const BattenGain& g : s.scan) EXPECT_LE(g.gain, bound * (1.0 + 1e-9));
      // The beat sits where the driver sees the fastest ratio: cos 2φ1 = −1.
      EXPECT_NEAR(std::cos(2.0 * s.best.phi1_rad), -1.0, 1e-6) << e;
      EXPECT_GE(s.best.phi02_rad, 0.0);
      EXPECT_LT(s.best.phi02_rad, kPi);  // one period of φ02 for k = 2
    }
  }
}

TEST(BattenDynamics, FrontSideIsTheHarderTurningPointWithTheCircularGear) {
  const BattenLinkage l(batten_004_dims());
  const BattenDrive circular(EllipticGearPair(kBatten004GearA_m, 0.0, 2), l, 0.0);
  const BattenBeatSide front = batten_front_side(l);
  const BattenBeatSide back =
      front == BattenBeatSide::kPsiMax ? BattenBeatSide::kPsiMin : BattenBeatSide::kPsiMax;
  const BattenBeat f = batten_beat(circular, front, 1.0), b = batten_beat(circular, back, 1.0);
  EXPECT_GE(std::abs(f.psi_ddot_rad_s2), std::abs(b.psi_ddot_rad_s2));
  EXPECT_EQ(f.beats_per_turn, 2);  // 004's double swing: two beats per crank turn
}

TEST(BattenDynamics, GearCrankLawMatchesFiniteDifferences) {
  const EllipticGearPair gear(kBatten004GearA_m, 0.25, 2);
  const double w = 3.0, h = 1e-5;
  for (int i = 0; i < 24; ++i) {
    const double p1 = kTwoPi * i / 24.0;
    const CrankMotion c = elliptic_gear_crank(gear, 0.4, p1, w);
    const double tm = elliptic_gear_crank(gear, 0.4, p1 - h * w, w).theta_rad;
    const double tp = elliptic_gear_crank(gear, 0.4, p1 + h * w, w).theta_rad;
    EXPECT_NEAR(c.omega_rad_s, (tp - tm) / (2 * h), 1e-7 * w);
    EXPECT_NEAR(c.alpha_rad_s2, (tp - 2 * c.theta_rad + tm) / (h * h), 1e-3 * w * w);
  }
}
