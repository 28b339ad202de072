// The sequencer's shed monitor against hand-made sensor pictures: a consistent picture opens the shed,
// an impossible one is a named verdict, and a whole stroke is trusted only once the frame can have made it.
#include "loom/sequencer/shed_monitor.hpp"

#include <gtest/gtest.h>

using namespace loom;
using loom::sequencer::PistonEnds;
using loom::sequencer::ShedMonitor;
using loom::sequencer::ShedVerdict;

namespace {
constexpr PistonEnds kExtended{true, false}, kRetracted{false, true}, kBetween{false, false},
    kBoth{true, true};

motion::ShedSpec spec() {
  motion::ShedSpec s;  // 0.25 s stroke, earliest 0.4, release 0.15 s, timeout 1.5 s, settle 20 ms
  return s;
}

// A stroke of A up from (retracted, retracted) arriving at `arrive_s`; the verdict when first not moving.
struct Result {
  ShedVerdict v;
  double t;
};
Result stroke_a_up(ShedMonitor& m, double arrive_s) {
  m.start(true, false, kRetracted, kRetracted);
  for (int i = 1; i < 1000; ++i) {
    const double t = i * 0.002;
    const ShedVerdict v =
        m.update(spec(), t, t < arrive_s ? (t < 0.01 ? kRetracted : kBetween) : kExtended, kRetracted);
    if (v != ShedVerdict::kMoving && v != ShedVerdict::kSettling) return {v, t};
  }
  return {ShedVerdict::kMoving, 2.0};
}
}  // namespace

TEST(ShedMonitor, AHealthyStrokeOpensAfterItsNominalTimeAndSettling) {
  ShedMonitor m;
  const Result r = stroke_a_up(m, 0.25);
  EXPECT_EQ(r.v, ShedVerdict::kOpen);
  EXPECT_NEAR(r.t, 0.25 + 0.02, 0.0021);
  EXPECT_NEAR(m.stroke_time_s(0, true), 0.25, 0.0021);  // learned
}

TEST(ShedMonitor, AnEndSensorAtTheProfilesEarliestWindowIsNotTrustedBeforeTheFrameCouldArrive) {
  // Confirmed at 0.15 s (60 % of the nominal stroke: inside the configured window), but the pick waits
  // until the nominal stroke time has passed: a sensor stuck on there cannot open a half-open shed.
  ShedMonitor m;
  const Result r = stroke_a_up(m, 0.15);
  EXPECT_EQ(r.v, ShedVerdict::kOpen);
  EXPECT_GE(r.t, 0.25 + 0.02 - 1e-9);
}

TEST(ShedMonitor, AStrokeFarFasterThanThisFrameLastMadeIsASensorFault) {
  ShedMonitor m;
  ASSERT_EQ(stroke_a_up(m, 0.30).v, ShedVerdict::kOpen);      // learns 0.30 s
  EXPECT_EQ(stroke_a_up(m, 0.20).v, ShedVerdict::kTooEarly);  // < 0.8 × 0.30
  ShedMonitor fresh;
  EXPECT_EQ(stroke_a_up(fresh, 0.05).v, ShedVerdict::kTooEarly);  // < 0.4 × 0.25 (the profiles' window)
}

TEST(ShedMonitor, AfterLearningThePickWaitsForTheLearnedStroke) {
  ShedMonitor m;
  ASSERT_EQ(stroke_a_up(m, 0.40).v, ShedVerdict::kOpen);  // a slow frame (low air): learns 0.40 s
  const Result r = stroke_a_up(m, 0.34);                  // a sensor that makes at 85 % of it
  EXPECT_EQ(r.v, ShedVerdict::kOpen);
  EXPECT_GE(r.t, 0.40 + 0.02 - 1e-9);
}

TEST(ShedMonitor, BothEndsOfOnePistonOnIsAConflict) {
  ShedMonitor m;
  m.start(true, false, kRetracted, kRetracted);
  EXPECT_EQ(m.update(spec(), 0.01, kBoth, kRetracted), ShedVerdict::kConflict);
  EXPECT_EQ(m.update(spec(), 0.02, kExtended, kRetracted), ShedVerdict::kConflict);  // latched
}

TEST(ShedMonitor, NeitherFrameLeavingIsAirLossOneIsNotReleased) {
  ShedMonitor both;
  both.start(false, true, kExtended, kRetracted);  // A down, B up: both must move
  EXPECT_EQ(both.update(spec(), 0.16, kExtended, kRetracted), ShedVerdict::kAirLost);
  ShedMonitor one;
  one.start(false, true, kExtended, kRetracted);
  EXPECT_EQ(one.update(spec(), 0.16, kBetween, kRetracted), ShedVerdict::kNotReleased);
}

TEST(ShedMonitor, AFrameLeftMidStrokeMayArriveAnyTime) {
  ShedMonitor m;
  m.start(true, false, kBetween, kRetracted);  // a power cut mid shed change
  EXPECT_EQ(m.update(spec(), 0.01, kExtended, kRetracted), ShedVerdict::kSettling);
  EXPECT_EQ(m.update(spec(), 0.04, kExtended, kRetracted), ShedVerdict::kOpen);
}

TEST(ShedMonitor, AStrokeFarSlowerThanLearnedIsAFrameStuckOnItsWay) {
  ShedMonitor m;
  ASSERT_EQ(stroke_a_up(m, 0.30).v, ShedVerdict::kOpen);
  const Result late = stroke_a_up(m, 0.50);  // > 1.25 × 0.30 + 0.02
  EXPECT_EQ(late.v, ShedVerdict::kTooLate);
  EXPECT_NEAR(late.t, 1.25 * 0.30 + 0.02, 0.0021);
}
