// Shedding windows, judged against a simple model of two pistons (a delay, then a stroke at constant
// speed, end sensors made at the ends): a healthy change opens after stroke + debounce + settle; a
// frame already in place needs no stroke; a sensor that confirms too early, a frame that never
// leaves its start sensor, and a stroke that never ends are each their own fault, at their time.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "loom/motion/errors.hpp"
#include "loom/motion/profile_shed.hpp"

using namespace loom::motion;

namespace {

constexpr double kTick = 0.002;

// Piston position 0 (retracted) … 1 (extended) after switching toward `extend` at t = 0.
struct Piston {
  double start = 0.0;      // position at t = 0
  double delay_s = 0.0;    // valve and breakaway
  double stroke_s = 0.25;  // full stroke time; infinite = stuck
  bool extend = true;
  double at(double t) const {
    const double moved = std::isfinite(stroke_s) ? std::max(0.0, t - delay_s) / stroke_s : 0.0;
    return extend ? std::min(1.0, start + moved) : std::max(0.0, start - moved);
  }
  PistonEnds ends(double t) const { return {at(t) >= 1.0, at(t) <= 0.0}; }
};

struct Outcome {
  ShedVerdict verdict = ShedVerdict::kMoving;
  double at_s = -1.0;  // first tick with a final verdict (open or a fault)
};

// Ticks until the monitor opens or faults (or 3 s pass). `tamper` may rewrite the sensor readings.
Outcome run(const ShedSpec& spec, Piston a, Piston b,
            const std::function<void(double, PistonEnds&, PistonEnds&)>& tamper = nullptr) {
  ShedMonitor m;
  PistonEnds a0 = a.ends(0), b0 = b.ends(0);
  if (tamper) tamper(0, a0, b0);
  m.start(a.extend, b.extend, a0, b0);
  for (int k = 0; k < 1500; ++k) {
    const double t = k * kTick;
    PistonEnds ea = a.ends(t), eb = b.ends(t);
    if (tamper) tamper(t, ea, eb);
    const ShedVerdict v = m.update(spec, t, ea, eb);
    if (v == ShedVerdict::kOpen || is_fault(v)) return {v, t};
  }
  return {};
}

// Raw (undebounced) sensors here, so the monitor debounces: 3 ticks.
const ShedSpec kSpec{.debounce_s = 0.006};

const Piston kRising{.start = 0.0, .extend = true};
const Piston kFalling{.start = 1.0, .extend = false};

}  // namespace

TEST(Shed, HealthyChangeOpensAfterStrokeDebounceAndSettle) {
  const ShedSpec s = kSpec;
  const Outcome o = run(s, kRising, kFalling);
  EXPECT_EQ(o.verdict, ShedVerdict::kOpen);
  // The pattern appears on the first tick at or after the stroke; open debounce + settle later.
  const double appears = std::ceil(s.piston_travel_s / kTick - 1e-9) * kTick;
  const double expected = appears + std::ceil((s.debounce_s + s.settle_s) / kTick - 1e-9) * kTick;
  EXPECT_GE(o.at_s, expected - 1e-9);
  EXPECT_LE(o.at_s, expected + kTick + 1e-9);  // time compared in floating point: one tick of slack
}

TEST(Shed, FramesAlreadyInPlaceOpenWithoutWaitingForAStroke) {
  const ShedSpec s = kSpec;
  const Outcome o = run(s, Piston{.start = 1.0, .extend = true}, Piston{.start = 0.0, .extend = false});
  EXPECT_EQ(o.verdict, ShedVerdict::kOpen);
  EXPECT_LE(o.at_s, s.debounce_s + s.settle_s + kTick);
}

TEST(Shed, SensorsConfirmingFasterThanAStrokeAreAFault) {
  const ShedSpec s = kSpec;
  // Miswired or stuck sensors: the commanded pattern reads true from the first tick after switching.
  const Outcome o = run(s, kRising, kFalling, [](double t, PistonEnds& a, PistonEnds& b) {
    if (t > 0) a = {true, false}, b = {false, true};
  });
  EXPECT_EQ(o.verdict, ShedVerdict::kTooEarly);
  EXPECT_LT(o.at_s, s.earliest_fraction * s.piston_travel_s);
  // A stroke just slower than the earliest bound is healthy.
  const Piston quick{.start = 0.0, .stroke_s = 0.45 * s.piston_travel_s, .extend = true};
  EXPECT_EQ(
      run(s, quick, Piston{.start = 1.0, .stroke_s = 0.45 * s.piston_travel_s, .extend = false}).verdict,
      ShedVerdict::kOpen);
}

TEST(Shed, FramesLeftMidStrokeMayArriveEarly) {
  // Power cut during a shed change: on restart the frames sit between their sensors and finish the
  // stroke in a fraction of the full time — healthy, not a sensor fault.
  const ShedSpec s = kSpec;
  const Outcome o = run(s, Piston{.start = 0.8, .extend = true}, Piston{.start = 0.2, .extend = false});
  EXPECT_EQ(o.verdict, ShedVerdict::kOpen);
  EXPECT_LT(o.at_s, s.earliest_fraction * s.piston_travel_s);
  // A frame that starts on its start sensor still must take a plausible stroke time.
  const Outcome miswired =
      run(s, kRising, Piston{.start = 0.2, .extend = false}, [](double t, PistonEnds& a, PistonEnds&) {
        if (t > 0) a = {true, false};
      });
  EXPECT_EQ(miswired.verdict, ShedVerdict::kTooEarly);
}

TEST(Shed, FrameThatNeverLeavesItsStartSensorFaultsAtTheReleaseTimeout) {
  const ShedSpec s = kSpec;
  const Piston stuck{.start = 0.0, .stroke_s = INFINITY, .extend = true};
  const Outcome o = run(s, stuck, kFalling);
  EXPECT_EQ(o.verdict, ShedVerdict::kNotReleased);
  EXPECT_GE(o.at_s, s.release_timeout_s - 1e-9);
  EXPECT_LE(o.at_s, s.release_timeout_s + kTick + 1e-9);
}

TEST(Shed, StrokeThatNeverEndsTimesOut) {
  const ShedSpec s = kSpec;
  const Piston slow{.start = 0.0, .stroke_s = 10.0, .extend = true};
  const Outcome o = run(s, slow, kFalling);
  EXPECT_EQ(o.verdict, ShedVerdict::kTimeout);
  EXPECT_GT(o.at_s, s.timeout_s);
  EXPECT_LE(o.at_s, s.timeout_s + kTick + 1e-12);
}

TEST(Shed, OneTickGlitchNeitherConfirmsNorTripsTooEarly) {
  const ShedSpec s = kSpec;
  const Outcome o = run(s, kRising, kFalling, [](double t, PistonEnds& a, PistonEnds& b) {
    if (std::abs(t - 0.05) < 1e-9) a = {true, false}, b = {false, true};  // two sensors bounce at once
  });
  EXPECT_EQ(o.verdict, ShedVerdict::kOpen);
  EXPECT_GT(o.at_s, s.piston_travel_s);
}

TEST(Shed, ABouncingStartSensorCannotRaiseNotReleased) {
  const ShedSpec s = kSpec;
  // Piston A leaves at once but its start sensor bounces back on for a tick after the release time.
  const Outcome o = run(s, kRising, kFalling, [&](double t, PistonEnds& a, PistonEnds&) {
    if (std::abs(t - (s.release_timeout_s + 0.01)) < 1e-9) a.retracted = true;
  });
  EXPECT_EQ(o.verdict, ShedVerdict::kOpen);
}

TEST(Shed, FaultVerdictIsLatched) {
  const ShedSpec s = kSpec;
  ShedMonitor m;
  m.start(true, false, {false, true}, {true, false});
  EXPECT_EQ(m.update(s, s.release_timeout_s, {false, true}, {false, false}), ShedVerdict::kNotReleased);
  // Even a perfect pattern afterwards does not clear it.
  EXPECT_EQ(m.update(s, 0.3, {true, false}, {false, true}), ShedVerdict::kNotReleased);
}

TEST(Shed, ContradictoryWindowsAreConfigErrorsNamingTheKey) {
  const auto message = [](ShedSpec s) -> std::string {
    try {
      validate(s);
    } catch (const MotionError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message(ShedSpec{}), "");
  EXPECT_NE(message(ShedSpec{.piston_travel_s = 2.0}).find("shedding.timeout_s = 1.5"), std::string::npos);
  EXPECT_NE(message(ShedSpec{.release_timeout_s = 2.0}).find("shedding.release_timeout_s = 2"),
            std::string::npos);
  EXPECT_NE(message(ShedSpec{.earliest_fraction = 1.0}).find("shedding.earliest_fraction"),
            std::string::npos);
  EXPECT_NE(message(ShedSpec{.debounce_s = -1}).find("shedding.debounce_s"), std::string::npos);
  EXPECT_NE(message(ShedSpec{.piston_travel_s = NAN}).find("shedding.piston_travel_s"), std::string::npos);
}
