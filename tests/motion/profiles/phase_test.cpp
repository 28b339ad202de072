// Fixed-point phase: exact wrap at one turn and across it, exact negation and n-fold steps, and a
// 10⁹-tick run whose accumulated phase equals the closed form N·step to the last unit — the
// property that lets the loop run for years without phase drift.
#include "loom/motion/phase.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "loom/motion/angles.hpp"

using namespace loom::motion;

namespace {
constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
}  // namespace

TEST(Phase, CarryAtExactlyOneTurn) {
  // Two halves make exactly one whole turn and nothing else.
  const Phase half{0, std::uint64_t{1} << 63};
  EXPECT_EQ(half + half, (Phase{1, 0}));
  // The last unit of a turn plus one unit is the next turn's start.
  EXPECT_EQ((Phase{0, kMax} + Phase{0, 1}), (Phase{1, 0}));
  EXPECT_EQ((Phase{-1, kMax} + Phase{0, 1}), (Phase{0, 0}));
}

TEST(Phase, NegationAndSubtractionAreExact) {
  for (const Phase p : {Phase{0, 0}, Phase{0, 1}, Phase{3, 12345}, Phase{-2, kMax}, Phase{5, 0}}) {
    EXPECT_EQ(p + (-p), (Phase{0, 0}));
    EXPECT_EQ((p - p), (Phase{0, 0}));
    EXPECT_EQ(-(-p), p);
  }
  EXPECT_EQ(-(Phase{0, 1}), (Phase{-1, kMax}));
  EXPECT_EQ((Phase{1, 0} - Phase{0, 1}), (Phase{0, kMax}));
}

TEST(Phase, FromRadWrapsAtExactlyOneTurn) {
  EXPECT_EQ(Phase::from_rad(kTwoPi), (Phase{1, 0}));
  EXPECT_EQ(Phase::from_rad(-kTwoPi), (Phase{-1, 0}));
  EXPECT_EQ(Phase::from_rad(3 * kTwoPi), (Phase{3, 0}));
  // Just below one turn stays in turn 0, its fraction within rounding of the whole turn.
  const Phase below = Phase::from_rad(std::nextafter(kTwoPi, 0.0));
  EXPECT_EQ(below.turns, 0);
  EXPECT_GT(below.frac, kMax - (std::uint64_t{1} << 12));
  // Just after the origin going backwards is the end of turn -1.
  const Phase behind = Phase::from_turns(-0.25);
  EXPECT_EQ(behind, (Phase{-1, std::uint64_t{3} << 62}));
}

TEST(Phase, RoundTripsThroughRadians) {
  for (double r : {0.0, 0.1, 1.0, 3.0, 6.2831, 100.0, -0.3, -57.0}) {
    EXPECT_NEAR(Phase::from_rad(r).to_rad(), r, 4e-15 * std::max(1.0, std::abs(r))) << r;
  }
}

TEST(Phase, SmallOffsetsAddWithinRounding) {
  // Across the turn boundary both ways, against the sum of the exact conversions.
  const Phase bases[] = {Phase{0, 5}, Phase{3, kMax - 7}, Phase{-1, std::uint64_t{1} << 63}};
  for (const Phase& base : bases) {
    for (double r : {0.0, 1e-12, -1e-12, 0.3, -0.3, 3.1, -3.1, 6.2, -6.2, 12.5, -12.5}) {
      const Phase got = base.plus_small_rad(r), want = base + Phase::from_rad(r);
      const Phase diff = got - want;
      const bool within =
          (diff.turns == 0 && diff.frac <= 16384) || (diff.turns == -1 && diff.frac >= kMax - 16384);
      EXPECT_TRUE(within) << r << ": " << diff.turns << " turns + " << diff.frac;
    }
  }
}

TEST(Phase, NonFiniteIsPhaseZeroAndHugeSaturates) {
  EXPECT_EQ(Phase::from_rad(std::nan("")), (Phase{0, 0}));
  EXPECT_EQ(Phase::from_rad(INFINITY), (Phase{0, 0}));
  EXPECT_EQ(Phase::from_turns(1e300).turns, std::int64_t{1} << 62);
  EXPECT_EQ(Phase::from_turns(-1e300).turns, -(std::int64_t{1} << 62));
}

TEST(Phase, TimesIsRepeatedAddition) {
  const Phase step{2, 0xDEADBEEFCAFEF00Dull};
  Phase sum{};
  for (int n = 0; n <= 1000; ++n) {
    EXPECT_EQ(step.times(n), sum) << n;
    EXPECT_EQ(step.times(-n), -sum) << n;
    sum += step;
  }
}

TEST(Phase, StepFromSpeedRejectsNonsense) {
  EXPECT_THROW(phase_step(NAN, 0.002), std::exception);
  EXPECT_THROW(phase_step(1.0, 0.0), std::exception);
  EXPECT_EQ(phase_step(0.0, 0.002), (Phase{0, 0}));  // a crank at rest stays exactly where it is
}

// 10⁹ ticks of a thousandth of a turn. The nearest fixed-point step is ⌈2^64/1000⌉ =
// 18446744073709552 units, 0.384 units too long (2^64 = 18446744073709551616), so after 10⁹ ticks
// the phase must be exactly 10⁶ turns plus 10⁹ × 0.384 = 384,000,000 units (1.3e-10 rad): the only
// error is the step's own rounding, never accumulated floating-point error.
TEST(PhaseDrift, BillionTicksEqualTheClosedForm) {
  PhaseClock clock({0, 0}, Phase::from_turns(1e-3));
  ASSERT_EQ(clock.step(), (Phase{0, 18446744073709552ull}));
  for (std::int64_t k = 0; k < 1'000'000'000; ++k) clock.tick();
  EXPECT_EQ(clock.phase(), (Phase{1'000'000, 384'000'000ull}));
}

// The loom's own numbers: 15.5 rad/s at a 2 ms tick. The accumulated phase equals N·step exactly,
// and stays within N × 2^-65 turn (half a unit per tick) of the exact ω·t, computed independently
// in extended precision.
TEST(PhaseDrift, BillionTicksAtCrankSpeedStayOnTheExactPhase) {
  const Phase step = phase_step(15.5, 0.002);
  PhaseClock clock({0, 0}, step);
  constexpr std::int64_t kTicks = 1'000'000'000;
  for (std::int64_t k = 0; k < kTicks; ++k) clock.tick();
  EXPECT_EQ(clock.phase(), step.times(kTicks));
  if constexpr (sizeof(long double) > sizeof(double)) {
    const long double exact_turns = static_cast<long double>(kTicks) * 15.5L *
                                    static_cast<long double>(0.002) /
                                    (2.0L * std::numbers::pi_v<long double>);
    const long double got = static_cast<long double>(clock.phase().turns) +
                            static_cast<long double>(clock.phase().frac) * 0x1p-64L;
    EXPECT_LE(std::fabs(got - exact_turns), static_cast<long double>(kTicks) * 0x1p-65L + 1e-12L);
  } else {
    GTEST_SKIP() << "no extended precision to compute the exact phase independently";
  }
}
