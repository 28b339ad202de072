// Tufting-needle six-bar (seed 002) against independent truth: the paper's own triangle route for
// θ3 (eqns 2-8), loop closure, dead-centre geometry, scale invariance, and finite differences of
// positions for every velocity and acceleration — with a constant and an accelerating main shaft.
#include "loom/motion/design/needle.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>

#include "finite_diff.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {
namespace {

constexpr double kOmega160rpm = 160.0 * kTwoPi / 60.0;  // 002's experiment speed

// θ3 by 002's eqns 2-8, transcribed: the triangle O-A-C with asin/acos. Valid for Table 1's branch.
double theta3_by_paper(const NeedleDims& d, double theta1) {
  const double phi1 = std::atan(d.x1_m / d.h1_m);
  const double l_oc = std::sqrt(d.h1_m * d.h1_m + d.x1_m * d.x1_m);
  const double phi4 = kPi / 2 - phi1 - theta1;
  const double l_ac = std::sqrt(d.l1_m * d.l1_m + l_oc * l_oc - 2 * d.l1_m * l_oc * std::cos(phi4));
  const double phi2 = std::asin(d.l1_m / l_ac * std::sin(phi4));
  const double phi3 =
      std::acos((l_ac * l_ac + d.l3_m * d.l3_m - d.l2_m * d.l2_m) / (2 * l_ac * d.l3_m)) - phi2;
  return 3 * kPi / 2 - phi1 - phi3;
}

TEST(Needle, ThetaThreeMatchesPaperTriangleRoute) {
  const NeedleDims d = needle_table1();
  const NeedleLinkage n(d);
  for (int i = 0; i < 3600; ++i) {
    const double t1 = kTwoPi * i / 3600.0;
    const NeedleState s = n.evaluate(t1, 1.0);
    EXPECT_NEAR(wrap_pi(s.theta3_rad - theta3_by_paper(d, t1)), 0.0, 1e-12) << "theta1 " << t1;
  }
}

// 002 eqn 9 takes θ2 from asin, which only reaches (-90°, 90°). With Table 1 the coupler A->B
// points up and to the left over the whole turn, so eqn 9 returns the mirror angle π - θ2.
TEST(Needle, PaperEquationNineReturnsTheWrongQuadrant) {
  const NeedleDims d = needle_table1();
  const NeedleLinkage n(d);
  for (int i = 0; i < 360; ++i) {
    const NeedleState s = n.evaluate(kTwoPi * i / 360.0, 1.0);
    EXPECT_LT(std::cos(s.theta2_rad), 0.0);
    const double eq9 =
        std::asin((d.l3_m * std::sin(s.theta3_rad) - d.l1_m * std::sin(s.theta1_rad) + d.h1_m) / d.l2_m);
    EXPECT_NEAR(eq9, kPi - s.theta2_rad, 1e-12);
  }
}

TEST(Needle, LoopClosureWithinOneTrillionthOfLargestLink) {
  const NeedleDims d = needle_table1();
  const NeedleLinkage n(d);
  double worst = 0.0;
  for (const NeedleState& s : needle_sweep(n, 3600, kOmega160rpm))
    worst = std::max(worst, n.closure_residual_m(s));
  EXPECT_LE(worst, 1e-12 * d.l6_m);
}

TEST(Needle, DeadCentresBoundTheRockerSwing) {
  const NeedleDims d = needle_table1();
  const NeedleLinkage n(d);
  const NeedleLinkage::RockerLimits lim = n.rocker_limits();
  // At a dead centre O, A, B are collinear, so the crank points at B; there the rocker stands still.
  for (double t3 : {lim.extended_rad, lim.folded_rad}) {
    const double bx = d.x1_m + d.l3_m * std::cos(t3);
    const double by = d.h1_m + d.l3_m * std::sin(t3);
    const bool extended = t3 == lim.extended_rad;
    const double t1 = std::atan2(by, bx) + (extended ? 0.0 : kPi);
    const NeedleState s = n.evaluate(t1, kOmega160rpm);
    EXPECT_NEAR(wrap_pi(s.theta3_rad - t3), 0.0, 1e-12);
    EXPECT_NEAR(s.omega3_rad_s, 0.0, 1e-9 * kOmega160rpm);
    EXPECT_NEAR(wrap_pi(s.theta2_rad - (extended ? t1 : t1 + kPi)), 0.0, 1e-10);
  }
  double lo = 1e9, hi = -1e9;
  for (const NeedleState& s : needle_sweep(n, 3600, 1.0)) {
    lo = std::min(lo, s.theta3_rad);
    hi = std::max(hi, s.theta3_rad);
  }
  const double swing = std::abs(wrap_pi(lim.extended_rad - lim.folded_rad));
  EXPECT_LE(hi - lo, swing + 1e-12);
  EXPECT_GE(hi - lo, swing - 1e-5);  // 0.1° sampling misses the exact extreme by O(step²)
}

TEST(Needle, SweepIsContinuousAndStaysOnBranch) {
  const NeedleLinkage n(needle_table1());
  const auto sw = needle_sweep(n, 3600, 1.0);
  ASSERT_EQ(sw.size(), 3600u);
  for (std::size_t i = 1; i < sw.size(); ++i) {
    EXPECT_LT(std::abs(sw[i].theta2_rad - sw[i - 1].theta2_rad), rad(0.5));
    EXPECT_LT(std::abs(sw[i].theta3_rad - sw[i - 1].theta3_rad), rad(0.5));
    EXPECT_LT(std::abs(sw[i].theta4_rad - sw[i - 1].theta4_rad), rad(0.5));
    EXPECT_LT(std::abs(sw[i].theta5_rad - sw[i - 1].theta5_rad), rad(0.5));
    EXPECT_LT(std::sin(sw[i].theta5_rad), 0.0);  // the rod hangs from D down to E (002's Fig. 2)
  }
  // One turn later every angle is back where it started: no branch was crossed.
  const NeedleState end = n.evaluate(kTwoPi, 1.0);
  EXPECT_NEAR(wrap_pi(end.theta3_rad - sw.front().theta3_rad), 0.0, 1e-12);
  EXPECT_NEAR(wrap_pi(end.theta5_rad - sw.front().theta5_rad), 0.0, 1e-12);
}

TEST(Needle, ThetaFourFollowsBetaOne) {
  const NeedleDims d = needle_table1();
  const NeedleLinkage n(d);
  for (int i = 0; i < 36; ++i) {
    const NeedleState s = n.evaluate(kTwoPi * i / 36.0, 1.0);
    EXPECT_NEAR(s.theta4_rad, s.theta3_rad + d.beta1_rad - kTwoPi, 1e-15);
    EXPECT_EQ(s.omega4_rad_s, s.omega3_rad_s);
    EXPECT_EQ(s.alpha4_rad_s2, s.alpha3_rad_s2);
  }
}

// ---- finite differences ----------------------------------------------------------------------

struct Motion {
  double theta0, omega0, alpha;  // θ1(t) = θ0 + ω0 t + α t²/2
  double angle(double t) const { return theta0 + omega0 * t + 0.5 * alpha * t * t; }
  double rate(double t) const { return omega0 + alpha * t; }
};

using Pick = std::function<double(const NeedleState&)>;

void check_rates_against_fd(const NeedleLinkage& n, double omega0, double alpha) {
  struct Channel {
    const char* name;
    Pick pos, vel, acc;
    bool angle;
  };
  const std::array<Channel, 5> ch{{
      {"theta2", [](const NeedleState& s) { return s.theta2_rad; },
       [](const NeedleState& s) { return s.omega2_rad_s; },
       [](const NeedleState& s) { return s.alpha2_rad_s2; }, true},
      {"theta3", [](const NeedleState& s) { return s.theta3_rad; },
       [](const NeedleState& s) { return s.omega3_rad_s; },
       [](const NeedleState& s) { return s.alpha3_rad_s2; }, true},
      {"theta4", [](const NeedleState& s) { return s.theta4_rad; },
       [](const NeedleState& s) { return s.omega4_rad_s; },
       [](const NeedleState& s) { return s.alpha4_rad_s2; }, true},
      {"theta5", [](const NeedleState& s) { return s.theta5_rad; },
       [](const NeedleState& s) { return s.omega5_rad_s; },
       [](const NeedleState& s) { return s.alpha5_rad_s2; }, true},
      {"needle", [](const NeedleState& s) { return s.needle_m; },
       [](const NeedleState& s) { return s.needle_v_m_s; },
       [](const NeedleState& s) { return s.needle_a_m_s2; }, false},
  }};
  constexpr int kPoints = 360;
  const double period = kTwoPi / omega0;
  const double h = 1e-3 / omega0;  // 1 mrad of crank travel
  for (const Channel& c : ch) {
    // Cycle scale of each rate, for the relative criterion.
    double vmax = 0.0, amax = 0.0;
    for (int i = 0; i < kPoints; ++i) {
      const double t = period * i / kPoints;
      const Motion m{0.3, omega0, alpha};
      const NeedleState s = n.evaluate(m.angle(t), m.rate(t), alpha);
      vmax = std::max(vmax, std::abs(c.vel(s)));
      amax = std::max(amax, std::abs(c.acc(s)));
    }
    for (int i = 0; i < kPoints; ++i) {
      const double t0 = period * i / kPoints;
      const Motion m{0.3, omega0, alpha};
      const NeedleState s0 = n.evaluate(m.angle(t0), m.rate(t0), alpha);
      const double p0 = c.pos(s0);
      const auto pos = [&](double t) {
        const double p = c.pos(n.evaluate(m.angle(t), m.rate(t), alpha));
        return c.angle ? p0 + wrap_pi(p - p0) : p;
      };
      const double v_fd = test::d1(pos, t0, h);
      const double a_fd = test::d2(pos, t0, h);
      EXPECT_TRUE(test::close_rel(c.vel(s0), v_fd, vmax, 1e-6))
          << c.name << " rate at t=" << t0 << ": " << c.vel(s0) << " vs fd " << v_fd;
      EXPECT_TRUE(test::close_rel(c.acc(s0), a_fd, amax, 1e-6))
          << c.name << " accel at t=" << t0 << ": " << c.acc(s0) << " vs fd " << a_fd;
    }
  }
}

TEST(Needle, RatesMatchFiniteDifferencesAtConstantSpeed) {
  check_rates_against_fd(NeedleLinkage(needle_table1()), kOmega160rpm, 0.0);
}

TEST(Needle, RatesMatchFiniteDifferencesWhileShaftAccelerates) {
  // Run-up of the main shaft: α1 enters α2, α3 (and through them the needle) — 002 assumes α1 = 0.
  check_rates_against_fd(NeedleLinkage(needle_table1()), kOmega160rpm, 40.0);
}

TEST(Needle, OtherRockerBranchCannotReachTheNeedleWithTableOne) {
  NeedleBranch b;
  b.rocker = NeedleRockerSide::kPinTowardNeedle;
  try {
    const NeedleLinkage n(needle_table1(), b);
    FAIL() << "expected kNotAssemblable";
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotAssemblable);
    EXPECT_NE(std::string(e.what()).find("l5"), std::string::npos) << e.what();
  }
}

TEST(Needle, StandingRodIsTheMirrorOfTheHangingRod) {
  NeedleBranch standing;
  standing.rod = NeedleRodSide::kStandingRod;
  const NeedleLinkage hanging_linkage(needle_table1());
  const NeedleLinkage standing_linkage(needle_table1(), standing);
  for (int i = 0; i < 36; ++i) {
    const double t1 = kTwoPi * i / 36.0;
    const NeedleState a = hanging_linkage.evaluate(t1, 1.0), b = standing_linkage.evaluate(t1, 1.0);
    EXPECT_NEAR(b.theta5_rad, -a.theta5_rad, 1e-15);
    EXPECT_NEAR(b.omega5_rad_s, -a.omega5_rad_s, 1e-12);
    EXPECT_LE(standing_linkage.closure_residual_m(b), 1e-12 * 0.44);
  }
}

}  // namespace
}  // namespace loom::motion
