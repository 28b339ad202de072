// The hard cases (label numeric): the phase wrap at exactly one turn and across it, the
// elliptic law at e → 0 reducing to constant speed exactly, a beat window too short for the carriage
// step (a configuration error naming the limits, at exactly the speed it names), the other refused
// recipes, and zero-length moves. The 10⁹-tick drift runs are in phase_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/profile_set.hpp"

using namespace loom::motion;

namespace {

PhaseExact wave(double p) {
  return {std::sin(p) + 0.3 * std::cos(3 * p) + 0.1 * std::sin(5 * p + 1),
          std::cos(p) - 0.9 * std::sin(3 * p) + 0.5 * std::cos(5 * p + 1),
          -std::sin(p) - 2.7 * std::cos(3 * p) - 2.5 * std::sin(5 * p + 1)};
}

// A cam-like function: the wave on a ramp that climbs kRise per turn.
constexpr double kRise = 0.0785714285714286;
PhaseExact rising(double p) {
  const PhaseExact w = wave(p);
  return {w.value + kRise * p / kTwoPi, w.d1 + kRise / kTwoPi, w.d2};
}

double max_error(const PhaseTable& t, PhaseExact (*f)(double)) {
  double e = 0;
  for (int i = 0; i < 20011; ++i) {
    const double p = kTwoPi * (i + 0.37) / 20011.0;
    e = std::max(e, std::abs(t.at(p).value - f(p).value));
  }
  return e;
}

constexpr Interp kOrders[] = {Interp::kLinear, Interp::kCubic, Interp::kQuintic};
constexpr Precision kPrecisions[] = {Precision::kDouble, Precision::kFloat};

const double kFell = BeatUp(default_beatup_geometry()).warp().fell;

CrankLaw elliptic(double e, int lobes, double phi02, const TableSpec& t) {
  return CrankLaw(
      {.kind = CrankLawKind::kElliptic, .ellipse_e = e, .ellipse_lobes = lobes, .ellipse_phi02_rad = phi02},
      kFell, t);
}

Phase weyl(int j) {
  return Phase{j % 7 - 3, 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(j + 1)};
}

std::string build_error(const ProfileSpec& s) {
  try {
    ProfileSet p(s);
  } catch (const MotionError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The wrap at exactly one turn and across it, for a rising (cam-like) table and every order and
// precision: one whole turn adds exactly `rise`, and the last unit of a turn meets the next turn.
TEST(PhaseTableWrap, ExactlyOneTurnAndAcross) {
  const double rise = kRise;
  for (Precision prec : kPrecisions) {
    for (Interp interp : kOrders) {
      const PhaseTable t({.size = 128, .interp = interp, .precision = prec, .rise = rise}, rising);
      const double order_bound = interp == Interp::kLinear ? 2e-3 : interp == Interp::kCubic ? 1e-5 : 1e-7;
      EXPECT_LT(max_error(t, rising), std::max(order_bound, prec == Precision::kFloat ? 3e-6 : 0.0))
          << interp_name(interp) << " " << precision_name(prec);
      const PhaseSample zero = t.at(Phase{0, 0});
      for (std::int64_t k = -3; k <= 3; ++k) {
        EXPECT_EQ(t.at(Phase{k, 0}).value, zero.value + rise * static_cast<double>(k));
        EXPECT_EQ(t.at(Phase{k, 0}).d1, zero.d1);
      }
      EXPECT_EQ(t.at(kTwoPi).value, zero.value + rise);  // 2π as a double is exactly one turn
      const PhaseSample before = t.at(Phase{0, std::numeric_limits<std::uint64_t>::max()});
      const PhaseSample after = t.at(Phase{1, 0});
      // Continuous across the turn: value for every order, slope for cubic and quintic (linear has
      // a kink at every knot, the turn boundary included); float32 to its rounding.
      const bool single = prec == Precision::kFloat;
      EXPECT_NEAR(before.value, after.value, single ? 1e-7 : 1e-15);
      if (interp != Interp::kLinear) {
        EXPECT_NEAR(before.d1, after.d1, single ? 1e-5 : 1e-12);
      }
      // Negative phases read the previous turn.
      EXPECT_NEAR(t.at(-0.25 * kTwoPi).value, t.at(0.75 * kTwoPi).value - rise, 1e-15);
    }
  }
}

TEST(PhaseTableWrap, NonFinitePhaseReadsPhaseZero) {
  for (Interp interp : kOrders) {
    const PhaseTable t({.size = 64, .interp = interp}, wave);
    EXPECT_EQ(t.at(std::nan("")).value, t.at(0.0).value);
    EXPECT_EQ(t.at(-INFINITY).value, t.at(0.0).value);
  }
}

TEST(CrankLawHard, EllipticAtZeroEccentricityIsConstantExactly) {
  for (Interp interp : {Interp::kLinear, Interp::kCubic, Interp::kQuintic}) {
    for (Precision prec : {Precision::kDouble, Precision::kFloat}) {
      const TableSpec t{.size = 128, .interp = interp, .precision = prec};
      const CrankLaw constant({.kind = CrankLawKind::kConstant}, kFell, t);
      const CrankLaw zero = elliptic(0.0, 1, kPi, t);
      const CrankLaw zero2 = elliptic(0.0, 2, 0.3, t);
      for (int j = 0; j < 5000; ++j) {
        const Phase m = weyl(j);
        const CrankSample a = constant.at(m), b = zero.at(m), c = zero2.at(m);
        EXPECT_EQ(a.phase, b.phase);
        EXPECT_EQ(a.d1, b.d1);
        EXPECT_EQ(a.d2, b.d2);
        EXPECT_EQ(a.phase, c.phase);
        EXPECT_EQ(a.phase, m.to_rad());  // constant speed: the crank is the master
        EXPECT_EQ(a.d1, 1.0);
        EXPECT_EQ(a.d2, 0.0);
        EXPECT_EQ(zero.crank_phase(m), m);
        const CrankLawExact x = zero.exact(m.to_rad());
        EXPECT_EQ(x.offset, 0.0);
        EXPECT_EQ(x.d1, 1.0);
        EXPECT_EQ(x.d2, 0.0);
        EXPECT_EQ(x.d3, 0.0);
      }
    }
  }
}

TEST(CrankLawHard, SmallEccentricityApproachesConstantLinearly) {
  double worst[2] = {0, 0};
  const double es[2] = {1e-6, 2e-6};
  for (int k = 0; k < 2; ++k) {
    const CrankLaw law = elliptic(es[k], 1, kPi, {.size = 256});
    for (int i = 0; i < 3600; ++i)
      worst[k] = std::max(worst[k], std::abs(law.exact(kTwoPi * i / 3600.0).offset));
  }
  EXPECT_GT(worst[0], 0.0);
  EXPECT_LT(worst[0], 4.1e-6);  // |φ2 − φ1| ≤ 2e/k to first order, twice that for the two brackets
  EXPECT_NEAR(worst[1] / worst[0], 2.0, 1e-4);  // linear in e
}

// The hard case: a beat window too short for the carriage step at the requested crank speed is a
// configuration error naming the limits — and the fastest feasible speed it names is right.
TEST(ProfileSetHard, TooShortBeatWindowNamesTheLimits) {
  ProfileSpec s;
  s.crank.velocity = 40.0;  // with a run-up short enough to reach it before the first beat
  s.crank.acceleration = 2000.0;
  s.crank.jerk = 1e5;
  const std::string msg = build_error(s);
  ASSERT_FALSE(msg.empty());
  for (const char* needle :
       {"carriage.max_speed_m_s = 1 (exceeded)", "carriage.max_accel_m_s2 = 20",
        "carriage.max_jerk_m_s3 = 2000", "recipe.crank_speed_rad_s", "deg of crank", "40 rad/s"}) {
    EXPECT_NE(msg.find(needle), std::string::npos) << needle << " not in: " << msg;
  }
  // The named speed is the boundary: just below builds, just above is refused.
  const ProfileSet ok(ProfileSpec{});
  const double fastest = ok.carriage_peaks().max_crank_speed_rad_s;
  EXPECT_GT(fastest, s.crank.velocity / 4);
  s.crank.velocity = fastest * 0.999;
  EXPECT_EQ(build_error(s), "");
  s.crank.velocity = fastest * 1.001;
  EXPECT_NE(build_error(s).find("(exceeded)"), std::string::npos);
}

TEST(ProfileSetHard, JerkLimitAloneIsEnforced) {
  ProfileSpec s;
  s.carriage_max_jerk_m_s3 = 200.0;  // the default step needs about 318 m/s^3
  const std::string msg = build_error(s);
  EXPECT_NE(msg.find("carriage.max_jerk_m_s3 = 200 (exceeded)"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("carriage.max_speed_m_s = 1 (exceeded)"), std::string::npos) << msg;
}

TEST(ProfileSetHard, RunUpTooLongForTheWindowIsRefused) {
  ProfileSpec s;
  s.crank.acceleration = 50.0;  // the crank would still be speeding up in the warp
  const std::string msg = build_error(s);
  EXPECT_NE(msg.find("cannot reach 15.5 rad/s before the first beat"), std::string::npos) << msg;
  EXPECT_NE(msg.find("recipe.crank_accel_rad_s2"), std::string::npos) << msg;
}

TEST(ProfileSetHard, TooCoarseTablesAreRefused) {
  ProfileSpec s;
  s.table_size = 32;
  s.table_interp = Interp::kLinear;
  const std::string msg = build_error(s);
  EXPECT_NE(msg.find("profiles.max_table_error_rad"), std::string::npos) << msg;
  EXPECT_NE(msg.find("32-knot linear double"), std::string::npos) << msg;
}

// Zero-length moves: a loom exactly one beater wide has one beat per row and a carriage that never
// moves; a zero-distance jerk move is at rest with zero duration.
TEST(ProfileSetHard, ZeroLengthMoves) {
  ProfileSpec s;
  s.width_m = s.beater_width_m;
  const ProfileSet p(s);
  EXPECT_EQ(p.beats_per_row(), 1);
  EXPECT_EQ(p.cam().steps(), 0);
  EXPECT_EQ(p.carriage_travel_m(), 0.0);
  EXPECT_EQ(p.carriage_peaks().speed_m_s, 0.0);
  for (int i = -10; i < 100; ++i) EXPECT_EQ(p.cam().at(0.1 * i).position, 0.0);
  const JerkMove zero = JerkMove::plan(0.0, s.helix);
  EXPECT_EQ(zero.duration(), 0.0);
  for (double t : {-1.0, 0.0, 0.5, 10.0}) {
    const MoveSample m = zero.at(t);
    EXPECT_EQ(m.position, 0.0);
    EXPECT_EQ(m.velocity, 0.0);
    EXPECT_EQ(m.acceleration, 0.0);
  }
  PhaseClock still({7, 123}, phase_step(0.0, 0.002));
  for (int i = 0; i < 1000; ++i) still.tick();
  EXPECT_EQ(still.phase(), (Phase{7, 123}));
}
