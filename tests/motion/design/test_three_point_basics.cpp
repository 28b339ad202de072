// Three-point synthesis, basic contract: a chain built by hand is recovered exactly, bad input is a
// typed error, and degenerate precision points (singular system) are reported, not solved.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/three_point.hpp"
#include "loom/motion/errors.hpp"
#include "motion_error.hpp"

namespace {

using loom::test::code_of_call;
using loom::test::message_of;

using loom::motion::ErrorCode;
using loom::motion::MotionError;
using loom::motion::PrecisionPoint;
using loom::motion::rad;
using loom::motion::three_point_synthesis;

// The chain end for given lengths and angles: the independent truth the synthesis must invert.
PrecisionPoint chain_end(double a0, double th0, double a1, double th1, double a2, double th2) {
  return {a0 * std::cos(th0) + a1 * std::cos(th1) + a2 * std::cos(th2),
          a0 * std::sin(th0) + a1 * std::sin(th1) + a2 * std::sin(th2), th2};
}

TEST(ThreePointBasics, RecoversAHandBuiltChain) {
  const double a0 = 20.0, a1 = 35.0, a2 = 15.0, th0 = rad(275.0);
  const std::array<PrecisionPoint, 3> pts = {chain_end(a0, th0, a1, rad(100), a2, rad(10)),
                                             chain_end(a0, th0, a1, rad(80), a2, rad(3)),
                                             chain_end(a0, th0, a1, rad(60), a2, rad(-25))};
  const auto result = three_point_synthesis(pts, th0);
  bool found = false;
  for (const auto& s : result.solutions) {
    EXPECT_LE(s.closure_residual, 1e-12 * std::max({std::fabs(s.a0), s.a1, std::fabs(s.a2)}));
    if (std::fabs(s.a0 - a0) < 1e-9 * a0 && std::fabs(s.a1 - a1) < 1e-9 * a1 &&
        std::fabs(s.a2 - a2) < 1e-9 * a2) {
      found = true;
      EXPECT_NEAR(s.theta1_rad[0], rad(100), 1e-12);
      EXPECT_NEAR(s.theta1_rad[1], rad(80), 1e-12);
      EXPECT_NEAR(s.theta1_rad[2], rad(60), 1e-12);
      EXPECT_NEAR(s.lambda, 1.0 / (a0 * a2), 1e-12 / (a0 * a2));
    }
  }
  EXPECT_TRUE(found);
}

TEST(ThreePointBasics, BadInputIsATypedError) {
  std::array<PrecisionPoint, 3> pts = {PrecisionPoint{0, 0, 0.1}, PrecisionPoint{25, 15, 0.05},
                                       PrecisionPoint{30, 1, -0.4}};
  EXPECT_EQ(code_of_call([&] { three_point_synthesis(pts, std::nan("")); }), ErrorCode::kInvalidInput);
  pts[1].y = std::numeric_limits<double>::infinity();
  EXPECT_EQ(code_of_call([&] { three_point_synthesis(pts, 1.0); }), ErrorCode::kInvalidInput);
}

TEST(ThreePointBasics, DegeneratePointsAreSingular) {
  // Two identical precision points: only two independent equations.
  const std::array<PrecisionPoint, 3> twice = {PrecisionPoint{0, 0, 0.1}, PrecisionPoint{25, 15, 0.05},
                                               PrecisionPoint{25, 15, 0.05}};
  EXPECT_EQ(code_of_call([&] { three_point_synthesis(twice, rad(275)); }), ErrorCode::kSingular);
  // All points at the origin: the coefficient columns vanish.
  const std::array<PrecisionPoint, 3> origin = {PrecisionPoint{0, 0, 0.1}, PrecisionPoint{0, 0, 0.2},
                                                PrecisionPoint{0, 0, 0.3}};
  EXPECT_EQ(code_of_call([&] { three_point_synthesis(origin, rad(275)); }), ErrorCode::kSingular);
}

}  // namespace
