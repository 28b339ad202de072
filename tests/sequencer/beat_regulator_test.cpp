// The beat regulator and the sweep's warped clock (beat_regulator.hpp), each alone:
//   - the clock at scale 1 is the tick time, bit for bit (a loom without a load cell runs as before);
//   - a sweep played at changing speeds keeps the carriage still while the speed changes, keeps the
//     master's acceleration and jerk within the recipe's crank limits, beats every beat at a constant
//     speed, steps the carriage only at scale 1, and brakes at scale 1;
//   - the regulator, against a synthetic warp (F = g·s², g from a profile across the width times a drift
//     per row), settles on the band's middle and stays within its bounds.
#include "loom/sequencer/beat_regulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/profile_set.hpp"

using namespace loom;
using sequencer::BeatRegulator;
using sequencer::BeatRegulatorConfig;
using sequencer::SweepClock;

TEST(SweepClock, AtScaleOneItIsTheTickTimeBitForBit) {
  const motion::ProfileSet p{motion::ProfileSpec{}};
  SweepClock c;
  c.configure(p, 0.002, BeatRegulatorConfig{}, 90.0);
  c.start(1234);
  c.request(0, 1.0);
  for (hal::Tick t = 1234; t < 1234 + 4000; ++t) {
    const double expected = static_cast<double>(t - 1234) * 0.002;
    ASSERT_EQ(c.time_at(t), expected) << t;
    c.advance(t, p.crank_sweep().position_at(c.time_at(t)));
  }
  EXPECT_FALSE(c.warped());
}

namespace {
struct Played {
  std::vector<double> master, cam, scale;  // per tick
  std::vector<double> at_fell, reported;   // per beat: the speed as the crank passes the fell, beat_scale()
};

// Plays one sweep of `p` on the clock, asking each beat for scales[k % size] once the beat before it has
// left the warp (as the sequencer does when it publishes a beat), and the braking at scale 1.
Played play(const motion::ProfileSet& p, SweepClock& c, const std::vector<double>& scales, double dt) {
  Played out;
  c.start(0);
  c.request(0, scales[0]);
  const double exit = p.beatup().warp().exit, fell = p.beatup().warp().fell;
  int published = 0;
  double prev_time = 0.0;
  for (hal::Tick t = 0; t < 100000; ++t) {
    const double tau = c.time_at(t);
    const double m = p.crank_sweep().position_at(tau);
    c.advance(t, m);
    const double crank = p.crank_phase_at(motion::Phase::from_rad(m));
    out.master.push_back(m);
    out.cam.push_back(p.cam().position_at(crank));
    out.scale.push_back(t == 0 ? 1.0 : (tau - prev_time) / dt);
    prev_time = tau;
    if (out.at_fell.size() < static_cast<std::size_t>(p.beats_per_row()) &&
        crank >= motion::kTwoPi * static_cast<double>(out.at_fell.size()) + fell)
      out.at_fell.push_back(out.scale.back());
    while (published < p.beats_per_row() && crank >= motion::kTwoPi * published + exit) {
      out.reported.push_back(c.beat_scale());  // as the sequencer publishes the beat
      ++published;
      c.request(published, scales[static_cast<std::size_t>(published) % scales.size()]);
    }
    if (tau >= p.crank_sweep().duration() + 2 * dt) break;
  }
  return out;
}
}  // namespace

TEST(SweepClock, SpeedChangesOnlyWhileTheCarriageRestsWithinTheCrankLimitsAndItStepsAtScaleOne) {
  for (const motion::CrankLawKind law : {motion::CrankLawKind::kConstant, motion::CrankLawKind::kElliptic}) {
    motion::ProfileSpec spec;
    spec.crank_law.kind = law;
    const motion::ProfileSet p(spec);
    const double dt = 0.002;
    SweepClock c;
    const sequencer::BeatRegulatorLimits lim = c.configure(p, dt, BeatRegulatorConfig{}, 90.0);
    ASSERT_GT(lim.max_scale, 1.05);
    ASSERT_LT(lim.min_scale, 0.95);
    ASSERT_GT(lim.max_step, 0.02);
    // Alternate the extremes: every change is cut to what its window allows.
    const Played r = play(p, c, {lim.max_scale, lim.min_scale, 1.0, lim.max_scale}, dt);
    EXPECT_TRUE(c.warped());
    const std::size_t n = r.master.size();
    ASSERT_GT(n, 100u);
    EXPECT_NEAR(r.master.back(), motion::kTwoPi * p.beats_per_row(), 1e-9);  // the whole sweep, to rest
    int changing_ticks = 0;
    for (std::size_t i = 2; i + 1 < n; ++i) {
      // Where the clock's speed changes between two ticks, the carriage does not move around them.
      if (std::abs(r.scale[i] - r.scale[i - 1]) > 1e-12 && r.master[i] > p.crank_sweep().ramp_distance() &&
          r.master[i] < motion::kTwoPi * p.beats_per_row() - p.crank_sweep().ramp_distance()) {
        ++changing_ticks;
        EXPECT_EQ(r.cam[i - 1], r.cam[i]) << "tick " << i;
        EXPECT_EQ(r.cam[i], r.cam[i + 1]) << "tick " << i;
      }
      EXPECT_LE(r.scale[i], lim.max_scale + 1e-9);
      EXPECT_GE(r.scale[i], lim.min_scale - 1e-9);
      // The master's acceleration (second difference) within the recipe's, plus what one tick of jerk adds.
      const double accel = (r.master[i + 1] - 2.0 * r.master[i] + r.master[i - 1]) / (dt * dt);
      EXPECT_LE(std::abs(accel), spec.crank.acceleration + spec.crank.jerk * dt + 1e-6) << "tick " << i;
    }
    EXPECT_GT(changing_ticks, 10);
    // Every contact at a constant speed: from half-way between the warp entry and the fell to half-way
    // between the fell and the exit the master's speed does not change (between two ticks both inside:
    // r.scale[i] is the mean over the tick before i).
    const motion::WarpWindow& w = p.beatup().warp();
    const auto in_turn = [&](double master) {
      return std::fmod(p.crank_phase_at(motion::Phase::from_rad(master)), motion::kTwoPi);
    };
    const auto near_fell = [&](double master) {
      const double phase = in_turn(master);
      return phase > 0.5 * (w.enter + w.fell) && phase < 0.5 * (w.fell + w.exit);
    };
    int contact_ticks = 0, stepping_ticks = 0;
    for (std::size_t i = 2; i < n; ++i) {
      if (near_fell(r.master[i - 2]) && near_fell(r.master[i])) {
        ++contact_ticks;
        ASSERT_NEAR(r.scale[i], r.scale[i - 1], 1e-9)
            << "tick " << i << " (" << in_turn(r.master[i]) << " rad)";
      }
      // The carriage moves only at the recipe's speed: its steps and their settling are as open loop.
      if (r.cam[i] != r.cam[i - 1]) {
        ++stepping_ticks;
        ASSERT_NEAR(r.scale[i], 1.0, 1e-9) << "tick " << i;
      }
    }
    EXPECT_GT(contact_ticks, 100);
    EXPECT_GT(stepping_ticks, 100);
    // Some beats were beaten at another speed than the recipe's.
    int fast = 0, slow = 0;
    for (std::size_t i = 1; i < n; ++i) {
      if (near_fell(r.master[i - 1]) && near_fell(r.master[i])) {
        fast += r.scale[i] > 1.01;
        slow += r.scale[i] < 0.99;
      }
    }
    EXPECT_GT(fast, 10);
    EXPECT_GT(slow, 10);
    // Each beat's speed as reported when it is published is the one it met the fell at.
    ASSERT_EQ(r.reported.size(), static_cast<std::size_t>(p.beats_per_row()));
    ASSERT_EQ(r.at_fell.size(), r.reported.size());
    for (std::size_t k = 0; k < r.reported.size(); ++k) EXPECT_NEAR(r.reported[k], r.at_fell[k], 1e-9) << k;
    // The braking is played at scale 1: the sweep's own braking, shifted in time.
    const double brake_from = motion::kTwoPi * p.beats_per_row() - p.crank_sweep().ramp_distance();
    for (std::size_t i = 1; i < n; ++i) {
      if (r.master[i - 1] >= brake_from) {
        ASSERT_NEAR(r.scale[i], 1.0, 1e-9) << "tick " << i;
      }
    }
  }
}

namespace {
// A warp whose beat at scale 1 gives g(p, row) = 90 · profile(p) · (1 + 0.002·row).
double gain(int p, int positions, int row) {
  const double u = (p + 0.5) / positions;
  return 90.0 * (1.0 - 0.6 * u * (1.0 - u)) * (1.0 + 0.002 * row);
}
}  // namespace

TEST(BeatRegulator, SettlesOnTheBandsMiddleFromTheSecondRow) {
  BeatRegulator reg;
  constexpr int kPositions = 15;
  reg.configure(BeatRegulatorConfig{},
                {.target_n = 90.0, .min_scale = 0.85, .max_scale = 1.15, .max_step = 0.1}, kPositions);
  double s = reg.first_beat(0);
  EXPECT_EQ(s, 1.0);  // nothing known: the recipe's speed
  double worst_row1 = 0.0, worst_later = 0.0;
  for (int row = 0; row < 40; ++row) {
    for (int k = 0; k < kPositions; ++k) {
      const int p = row % 2 == 0 ? k : kPositions - 1 - k;  // sweeps alternate
      const int next = k + 1 < kPositions ? (row % 2 == 0 ? k + 1 : kPositions - 2 - k) : p;
      const double f = gain(p, kPositions, row) * s * s;
      (row == 0 ? worst_row1 : worst_later) =
          std::max(row == 0 ? worst_row1 : worst_later, std::abs(f - 90.0));
      s = reg.after_beat(p, s, true, f, next);
      EXPECT_GE(s, 0.85);
      EXPECT_LE(s, 1.15);
    }
  }
  EXPECT_LT(worst_row1, 5.0);   // the first row: the neighbour stands for the next place
  EXPECT_LT(worst_later, 0.5);  // remembered and drift-corrected: within half a newton of the middle
  EXPECT_EQ(reg.beats_learned(), 40u * kPositions);
}

TEST(BeatRegulator, BoundedAndOpenLoopWithoutMeasurements) {
  BeatRegulator reg;
  reg.configure(BeatRegulatorConfig{},
                {.target_n = 90.0, .min_scale = 0.9, .max_scale = 1.1, .max_step = 0.1}, 3);
  EXPECT_EQ(reg.after_beat(0, 1.0, false, 0.0, 1), 1.0);  // no load cell: nothing learned, nothing changed
  EXPECT_EQ(reg.after_beat(0, 1.0, true, std::nan(""), 1), 1.0);
  EXPECT_EQ(reg.after_beat(0, 1.0, true, 10.0, 1), 1.1);   // far too soft: as fast as allowed
  EXPECT_EQ(reg.after_beat(1, 1.1, true, 900.0, 2), 0.9);  // far too hard: as slow as allowed
  BeatRegulatorConfig off;
  off.enabled = false;
  reg.configure(off, {.target_n = 90.0, .min_scale = 0.9, .max_scale = 1.1, .max_step = 0.1}, 3);
  EXPECT_EQ(reg.after_beat(0, 1.0, true, 10.0, 1), 1.0);  // switched off: open loop
  EXPECT_EQ(reg.first_beat(0), 1.0);
}
