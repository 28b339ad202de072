// Jerk-limited move: reaches the distance exactly, respects every limit, and its derivatives agree
// with finite differences of its position, in all three planning cases.
#include "loom/motion/jerk_move.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/errors.hpp"

using namespace loom::motion;

namespace {
void check_move(double distance, const JerkLimits& l) {
  const JerkMove m = JerkMove::plan(distance, l);
  ASSERT_GT(m.duration(), 0.0);
  EXPECT_EQ(m.at(m.duration()).position, distance);
  EXPECT_EQ(m.at(m.duration() + 1).velocity, 0.0);
  const int n = 4000;
  const double h = 1e-6;
  for (int i = 1; i < n; ++i) {
    const double t = m.duration() * i / n;
    const MoveSample s = m.at(t);
    EXPECT_LE(std::abs(s.velocity), l.velocity * (1 + 1e-9));
    EXPECT_LE(std::abs(s.acceleration), l.acceleration * (1 + 1e-9));
    EXPECT_LE(std::abs(s.jerk), l.jerk * (1 + 1e-9));
    const MoveSample a = m.at(t - h), b = m.at(t + h);
    EXPECT_NEAR(s.velocity, (b.position - a.position) / (2 * h), 1e-6 * std::max(1.0, std::abs(distance)));
    // Across a jerk switch the central difference of a kinked acceleration is off by at most j·h/2.
    EXPECT_NEAR(s.acceleration, (b.velocity - a.velocity) / (2 * h), l.jerk * h);
  }
  // Position at the end of the run-up equals the published ramp distance.
  const MoveSample ramp_end = m.at(m.ramp_time());
  EXPECT_NEAR(std::abs(ramp_end.position), m.ramp_distance(), 1e-9 * std::abs(distance) + 1e-12);
}
}  // namespace

TEST(JerkMove, CruiseCaseReachesPeakVelocity) {
  const JerkLimits l{.velocity = 60, .acceleration = 2000, .jerk = 1e5};
  check_move(75.4, l);
  EXPECT_DOUBLE_EQ(JerkMove::plan(75.4, l).peak_velocity(), 60.0);
}

TEST(JerkMove, AccelerationPlateauWithoutCruise) {
  const JerkLimits l{.velocity = 60, .acceleration = 2000, .jerk = 1e5};
  check_move(1.5, l);
  EXPECT_LT(JerkMove::plan(1.5, l).peak_velocity(), 60.0);
}

TEST(JerkMove, PureJerkPhasesForTinyMoves) {
  const JerkLimits l{.velocity = 60, .acceleration = 2000, .jerk = 1e5};
  check_move(1e-4, l);
  check_move(-2e-3, l);  // negative direction
}

TEST(JerkMove, ZeroLengthMoveStaysAtRest) {
  const JerkMove m = JerkMove::plan(0.0, {.velocity = 1, .acceleration = 1, .jerk = 1});
  EXPECT_EQ(m.duration(), 0.0);
  EXPECT_EQ(m.at(0.5).position, 0.0);
  EXPECT_EQ(m.at(0.5).velocity, 0.0);
}

TEST(JerkMove, InvalidLimitsAreNamed) {
  try {
    validate({.velocity = 1, .acceleration = 0, .jerk = 1}, "helix");
    FAIL();
  } catch (const MotionError& e) {
    EXPECT_NE(std::string(e.what()).find("helix: acceleration"), std::string::npos);
  }
}
