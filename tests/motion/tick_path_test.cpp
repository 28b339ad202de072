// The tick's motion calls without libm (Phase::from_turns, CarriageCam::at) and their sampling
// shortcuts (JerkMove::position_at, CarriageCam::position_at, CrankLaw::phase_at) give the same bits as the
// formulas they replace: each reference below is the former formula written out with libm's floor, nearbyint,
// fmin, fmax and fmod, or the full sample the shortcut is a part of.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/motion/carriage_cam.hpp"
#include "loom/motion/jerk_move.hpp"
#include "loom/motion/phase.hpp"
#include "loom/motion/profile_crank.hpp"

using namespace loom::motion;

namespace {

std::uint64_t bits(double x) {
  return std::bit_cast<std::uint64_t>(x);
}

// Phase::from_turns as it was: fmax/fmin clamp, floor, nearbyint.
Phase from_turns_libm(double x) {
  if (!std::isfinite(x)) return {};
  constexpr double kSat = 4611686018427387904.0;  // 2^62
  x = std::fmin(std::fmax(x, -kSat), kSat);
  double whole = std::floor(x);
  const double rest = x - whole;
  double units = std::nearbyint(rest * 18446744073709551616.0);
  if (units >= 18446744073709551616.0) {
    whole += 1.0;
    units = 0.0;
  }
  return {static_cast<std::int64_t>(whole), static_cast<std::uint64_t>(units)};
}

// CarriageCam::at's staircase as it was (floor and fmod), from the cam's own window and pitch.
CamSample cam_libm(const CarriageCam& c, double phase) {
  if (!(phase > c.window_start()) || c.steps() == 0) return {};
  const double rel = phase - c.window_start();
  const double k = std::floor(rel / kTwoPi);
  const double n = static_cast<double>(c.beats_per_position());
  const double started = std::floor((k + 1.0) / n);
  const double total = static_cast<double>(c.steps());
  const double pitch = c.pitch();
  if (started > total || (started == total && std::fmod(k + 1.0, n) != 0.0))
    return {pitch * total, 0.0, 0.0, 0.0};
  if (std::fmod(k + 1.0, n) != 0.0) return {pitch * started, 0.0, 0.0, 0.0};
  const double u = (rel - k * kTwoPi) / c.window_length();
  const CamSample s = smooth_step(u);
  const double l = 1.0 / c.window_length();
  return {pitch * (started - 1.0 + s.position), pitch * s.d1 * l, pitch * s.d2 * l * l,
          pitch * s.d3 * l * l * l};
}

}  // namespace

TEST(TickPath, FromTurnsIsTheLibmFormulaBitForBit) {
  std::vector<double> xs{0.0,
                         -0.0,
                         1.0,
                         -1.0,
                         0.5,
                         -0.5,
                         1e-300,
                         -1e-300,
                         5e-324,
                         -5e-324,
                         1e-20,
                         -1e-20,
                         0x1p52,
                         -0x1p52,
                         0x1p62,
                         -0x1p62,
                         0x1p63,
                         -0x1p63,
                         1e300,
                         -1e300,
                         std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity(),
                         std::numeric_limits<double>::quiet_NaN(),
                         std::nextafter(1.0, 0.0),
                         std::nextafter(-1.0, 0.0),
                         std::nextafter(0x1p62, 0.0),
                         std::nextafter(-0x1p62, 0.0)};
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-80, 70);
  for (int i = 0; i < 400000; ++i) xs.push_back(std::ldexp(mantissa(rng), exponent(rng)));
  // Whole turns and their neighbours, and phases of many turns as the sweep makes them (rad / 2π).
  for (int k = -2000; k <= 2000; ++k) {
    const double w = k;
    xs.insert(xs.end(), {w, std::nextafter(w, -1e300), std::nextafter(w, 1e300), (k * 0.37) / kTwoPi});
  }
  for (const double x : xs) {
    const Phase got = Phase::from_turns(x), want = from_turns_libm(x);
    ASSERT_EQ(got.turns, want.turns) << x;
    ASSERT_EQ(got.frac, want.frac) << x;
  }
}

TEST(TickPath, CarriageCamIsTheFloorAndFmodFormulaBitForBit) {
  const BeatUp b(default_beatup_geometry());
  for (const int per : {1, 2, 3, 4, 7}) {
    for (const int steps : {0, 1, 5, 40}) {
      const CarriageCam cam(b.warp(), rad(20), 0.008, steps, per);
      std::vector<double> phases{-1.0, 0.0, cam.window_start(), 1e300,
                                 std::numeric_limits<double>::infinity()};
      const int turns = (steps + 2) * per + 2;
      for (int i = 0; i <= 200000; ++i) phases.push_back(-0.5 + (turns * kTwoPi + 1.0) * i / 200000.0);
      for (int k = 0; k <= turns; ++k) {  // every window's start and end, exactly and one ulp either side
        for (const double p :
             {cam.window_start() + k * kTwoPi, cam.window_start() + k * kTwoPi + cam.window_length()}) {
          phases.insert(phases.end(), {p, std::nextafter(p, -1e300), std::nextafter(p, 1e300)});
        }
      }
      for (const double p : phases) {
        const CamSample got = cam.at(p), want = cam_libm(cam, p);
        ASSERT_EQ(bits(cam.position_at(p)), bits(want.position)) << "position_at, phase " << p;
        ASSERT_EQ(bits(got.position), bits(want.position))
            << "per " << per << " steps " << steps << " phase " << p;
        ASSERT_EQ(bits(got.d1), bits(want.d1)) << p;
        ASSERT_EQ(bits(got.d2), bits(want.d2)) << p;
        ASSERT_EQ(bits(got.d3), bits(want.d3)) << p;
      }
    }
  }
}

TEST(TickPath, PositionAtIsTheSamplesPosition) {
  const JerkLimits l{.velocity = 2.0, .acceleration = 20.0, .jerk = 400.0};
  for (const double d : {0.0, 1e-9, -1e-3, 0.05, -0.7, 3.0, 40.0}) {
    const JerkMove m = JerkMove::plan(d, l);
    for (int i = -100; i <= 100100; ++i) {
      const double t = m.duration() * i / 100000.0;
      ASSERT_EQ(bits(m.position_at(t)), bits(m.at(t).position)) << "distance " << d << " t " << t;
    }
    for (const double t : {-1e300, 1e300, std::numeric_limits<double>::quiet_NaN()}) {
      ASSERT_EQ(bits(m.position_at(t)), bits(m.at(t).position)) << t;
    }
  }
}

TEST(TickPath, CrankPhaseAtIsTheSamplesPhase) {
  const double fell = BeatUp(default_beatup_geometry()).warp().fell;
  const TableSpec table{.size = 256, .interp = Interp::kCubic, .precision = Precision::kDouble};
  const CrankLaw constant(CrankLawSpec{}, fell, table);
  const CrankLaw elliptic(
      {.kind = CrankLawKind::kElliptic, .ellipse_e = 0.3, .ellipse_lobes = 1, .ellipse_phi02_rad = kPi}, fell,
      table);
  for (int j = -3000; j <= 300000; ++j) {
    const Phase m = Phase::from_rad(j * 0.00123);
    ASSERT_EQ(bits(constant.phase_at(m)), bits(constant.at(m).phase)) << j;
    ASSERT_EQ(bits(elliptic.phase_at(m)), bits(elliptic.at(m).phase)) << j;
    // The constant law is the identity: its table adds nothing.
    ASSERT_EQ(constant.table().at(m).value, 0.0) << j;
  }
}
