// Beat-up head: the default thesis linkage, its warp window, the carriage cam that steps only while
// the beater is clear, and the smooth step's derivatives against finite differences.
#include "loom/motion/beatup.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/angles.hpp"
#include "loom/motion/carriage_cam.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/phase_table.hpp"

using namespace loom::motion;

TEST(BeatUp, DefaultLinkageWindowIsOrderedAndConsistent) {
  const BeatUp b(default_beatup_geometry());
  const WarpWindow& w = b.warp();
  EXPECT_GT(w.enter, 0.0);
  EXPECT_LT(w.enter, w.fell);
  EXPECT_LT(w.fell, w.exit);
  EXPECT_LT(w.exit, kTwoPi);
  EXPECT_NEAR(b.at(w.enter).from_fell_m, 0.05, 1e-9);
  EXPECT_NEAR(b.at(w.exit).from_fell_m, 0.05, 1e-9);
  EXPECT_NEAR(b.at(w.fell).from_fell_m, 0.0, 1e-9);
  EXPECT_NEAR(b.at(w.fell).d1, 0.0, 1e-9);  // dead centre: rocker at rest
  EXPECT_FALSE(b.at(0.0).in_warp);
  for (int i = 0; i < 3600; ++i) {
    const double p = kTwoPi * i / 3600.0;
    EXPECT_EQ(b.at(p).in_warp, p > w.enter && p < w.exit) << p;
  }
  // Stroke of the beater tip: arm × swing, about 17 cm for the thesis linkage.
  EXPECT_NEAR(b.stroke_arc_m(), 0.301 * b.dead_centres().swing, 1e-15);
  EXPECT_GT(b.stroke_arc_m(), 0.12);
}

TEST(BeatUp, WarpDepthOutsideTheStrokeIsRejected) {
  BeatUpGeometry g = default_beatup_geometry();
  g.warp_depth_m = 0.5;
  EXPECT_THROW(BeatUp{g}, MotionError);
}

TEST(BeatUp, RockerTableMatchesExactKinematics) {
  const BeatUp b(default_beatup_geometry());
  const PhaseTable t(4096, [&](double p) {
    const BeaterState s = b.at(p);
    return PhaseTable::Exact{s.rocker_angle, s.d1};
  });
  double err = 0;
  for (int i = 0; i < 9973; ++i) {
    const double p = kTwoPi * i / 9973.0;
    err = std::max(err, std::abs(t.at(p).value - b.at(p).rocker_angle));
  }
  EXPECT_LT(err, 1e-9);
}

TEST(CarriageCam, SmoothStepDerivativesMatchFiniteDifferences) {
  const double h = 1e-6;
  for (int i = 1; i < 100; ++i) {
    const double u = i / 100.0;
    const CamSample s = smooth_step(u), a = smooth_step(u - h), c = smooth_step(u + h);
    EXPECT_NEAR(s.d1, (c.position - a.position) / (2 * h), 1e-7);
    EXPECT_NEAR(s.d2, (c.d1 - a.d1) / (2 * h), 1e-6);
    EXPECT_NEAR(s.d3, (c.d2 - a.d2) / (2 * h), 1e-5);
  }
  EXPECT_EQ(smooth_step(0).position, 0.0);
  EXPECT_EQ(smooth_step(1).position, 1.0);
}

TEST(CarriageCam, MovesOnlyWhileTheBeaterIsClear) {
  const BeatUp b(default_beatup_geometry());
  const CarriageCam cam(b.warp(), rad(5), 0.08, 14);
  double prev = 0.0;
  for (int i = 0; i <= 15 * 3600; ++i) {
    const double phi = kTwoPi * i / 3600.0;
    const CamSample s = cam.at(phi);
    if (b.at(phi).in_warp) {
      EXPECT_EQ(s.position, prev) << "carriage moved in the warp at phase " << phi;
      EXPECT_EQ(s.d1, 0.0);
    }
    EXPECT_GE(s.position, prev);
    prev = s.position;
  }
  EXPECT_DOUBLE_EQ(prev, 0.08 * 14);
  // The carriage sits at an exact multiple of the pitch at every fell (beat) of turn k.
  for (int k = 0; k < 15; ++k) EXPECT_DOUBLE_EQ(cam.at(k * kTwoPi + b.warp().fell).position, 0.08 * k);
}

TEST(CarriageCam, BeatsEveryPositionSeveralTimesBeforeStepping) {
  const BeatUp b(default_beatup_geometry());
  const int per = 3, steps = 4;
  const CarriageCam cam(b.warp(), rad(20), 0.08, steps, per);
  // Beat k (k = 0 … (steps+1)·per − 1) happens at the fell of turn k, at position floor(k / per).
  for (int k = 0; k < (steps + 1) * per; ++k) {
    EXPECT_DOUBLE_EQ(cam.at(k * kTwoPi + b.warp().fell).position, 0.08 * (k / per)) << "beat " << k;
  }
  // Still never in the warp, still monotone, and the last position is held.
  double prev = 0.0;
  for (int i = 0; i <= (steps + 1) * per * 720; ++i) {
    const double phi = kTwoPi * i / 720.0;
    const CamSample s = cam.at(phi);
    if (b.at(phi).in_warp) {
      EXPECT_EQ(s.d1, 0.0);
    }
    EXPECT_GE(s.position, prev);
    prev = s.position;
  }
  EXPECT_DOUBLE_EQ(prev, 0.08 * steps);
  EXPECT_THROW(CarriageCam(b.warp(), rad(20), 0.08, steps, 0), MotionError);
}
