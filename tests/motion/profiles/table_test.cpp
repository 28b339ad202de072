// Phase tables: each kernel reproduces the polynomials of its own degree exactly, converges at its
// order (h², h⁴, h⁶ in position) on a smooth function, is continuous to its order across every knot
// including the turn boundary, and float32 knots keep their accuracy far from zero (base offset).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/phase_table.hpp"

using namespace loom::motion;

namespace {

constexpr Interp kOrders[] = {Interp::kLinear, Interp::kCubic, Interp::kQuintic};
constexpr Precision kPrecisions[] = {Precision::kDouble, Precision::kFloat};

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

struct Errors {
  double value = 0, d1 = 0, d2 = 0;
};

// Worst errors at 20011 phases spread over the turn (never on knots of the sizes used).
Errors errors(const PhaseTable& t, PhaseExact (*f)(double)) {
  Errors e;
  for (int i = 0; i < 20011; ++i) {
    const double p = kTwoPi * (i + 0.37) / 20011.0;
    const PhaseSample s = t.at(p);
    const PhaseExact x = f(p);
    e.value = std::max(e.value, std::abs(s.value - x.value));
    e.d1 = std::max(e.d1, std::abs(s.d1 - x.d1));
    e.d2 = std::max(e.d2, std::abs(s.d2 - x.d2));
  }
  return e;
}

PhaseTable table(std::size_t n, Interp i, Precision p = Precision::kDouble, double rise = 0.0,
                 PhaseExact (*f)(double) = wave) {
  return PhaseTable({.size = n, .interp = i, .precision = p, .rise = rise}, f);
}

}  // namespace

// Inside the turn (away from the wrap segment, where the knots come from the other end) a kernel
// of degree d reproduces any polynomial of degree d to rounding.
TEST(PhaseTable, KernelsReproducePolynomialsOfTheirDegree) {
  const auto poly = [](int degree) {
    return [degree](double p) {
      // c_k = 1/(k+1), so value = Σ p^k/(k+1) and its derivatives follow.
      PhaseExact e;
      for (int k = 0; k <= degree; ++k) {
        const double c = 1.0 / (k + 1);
        e.value += c * std::pow(p, k);
        if (k >= 1) e.d1 += c * k * std::pow(p, k - 1);
        if (k >= 2) e.d2 += c * k * (k - 1) * std::pow(p, k - 2);
      }
      return e;
    };
  };
  const std::pair<Interp, int> cases[] = {{Interp::kLinear, 1}, {Interp::kCubic, 3}, {Interp::kQuintic, 5}};
  for (const auto& [interp, degree] : cases) {
    const auto f = poly(degree);
    const PhaseTable t({.size = 16, .interp = interp}, f);
    const double last_inner = kTwoPi * 15.0 / 16.0;
    for (int i = 0; i < 1000; ++i) {
      const double p = last_inner * (i + 0.5) / 1000.0;
      const PhaseSample s = t.at(p);
      const PhaseExact x = f(p);
      EXPECT_NEAR(s.value, x.value, 1e-11 * std::max(1.0, std::abs(x.value)))
          << interp_name(interp) << " at " << p;
      EXPECT_NEAR(s.d1, x.d1, 1e-10 * std::max(1.0, std::abs(x.d1))) << interp_name(interp) << " at " << p;
      if (interp != Interp::kLinear) {
        EXPECT_NEAR(s.d2, x.d2, 1e-8 * std::max(1.0, std::abs(x.d2))) << interp_name(interp) << " at " << p;
      }
    }
  }
}

TEST(PhaseTable, ErrorsConvergeAtEachOrder) {
  struct Expect {
    Interp interp;
    std::size_t n;
    double value_ratio, d1_ratio, d2_ratio;  // ideal ratios e(n)/e(2n)
  };
  const Expect cases[] = {
      {Interp::kLinear, 256, 4, 2, 0}, {Interp::kCubic, 64, 16, 8, 4}, {Interp::kQuintic, 32, 64, 32, 16}};
  for (const Expect& c : cases) {
    const Errors a = errors(table(c.n, c.interp), wave), b = errors(table(2 * c.n, c.interp), wave);
    EXPECT_GT(a.value / b.value, 0.75 * c.value_ratio) << interp_name(c.interp);
    EXPECT_GT(a.d1 / b.d1, 0.75 * c.d1_ratio) << interp_name(c.interp);
    if (c.d2_ratio > 0) {
      EXPECT_GT(a.d2 / b.d2, 0.75 * c.d2_ratio) << interp_name(c.interp);
    }
  }
  // And the absolute levels that make cubic the workhorse: 256 knots already below 1e-7.
  EXPECT_LT(errors(table(256, Interp::kCubic), wave).value, 1e-7);
  EXPECT_LT(errors(table(256, Interp::kQuintic), wave).value, 1e-11);
}

// Continuity across every knot, including the turn boundary: value for all orders, slope for cubic
// and quintic, curvature for quintic. One unit (2^-64 turn) either side of the knot.
TEST(PhaseTable, ContinuousToItsOrderAcrossEveryKnot) {
  const std::size_t n = 64;
  for (Interp interp : kOrders) {
    const PhaseTable t = table(n, interp, Precision::kDouble, kRise, rising);
    for (std::size_t k = 0; k <= n; ++k) {
      const Phase knot = Phase::from_turns(static_cast<double>(k) / n);
      const PhaseSample left = t.at(knot - Phase{0, 1}), right = t.at(knot + Phase{0, 1});
      EXPECT_NEAR(left.value, right.value, 1e-12) << interp_name(interp) << " knot " << k;
      if (interp != Interp::kLinear) {
        EXPECT_NEAR(left.d1, right.d1, 1e-9) << interp_name(interp) << " knot " << k;
      }
      if (interp == Interp::kQuintic) {
        EXPECT_NEAR(left.d2, right.d2, 1e-6) << interp_name(interp) << " knot " << k;
      }
    }
  }
}

// float32 knots store the offset from the table's mid value: a function living near -2.5 rad (the
// rocker does) keeps float32's relative precision on its swing, not on its magnitude.
TEST(PhaseTable, Float32KnotsKeepTheirPrecisionFarFromZero) {
  const auto far = [](double p) {
    const PhaseExact w = wave(p);
    return PhaseExact{-2.5 + 0.1 * w.value, 0.1 * w.d1, 0.1 * w.d2};
  };
  const PhaseTable f({.size = 1024, .interp = Interp::kCubic, .precision = Precision::kFloat}, far);
  const PhaseTable d({.size = 1024, .interp = Interp::kCubic, .precision = Precision::kDouble}, far);
  double ef = 0, ed = 0;
  for (int i = 0; i < 20011; ++i) {
    const double p = kTwoPi * (i + 0.37) / 20011.0;
    ef = std::max(ef, std::abs(f.at(p).value - far(p).value));
    ed = std::max(ed, std::abs(d.at(p).value - far(p).value));
  }
  // Half an ulp of 2.5 in float32 is 1.2e-7; of the swing (≈0.15) it is 7e-9.
  EXPECT_LT(ef, 3e-8);
  EXPECT_LT(ed, 1e-10);
  EXPECT_EQ(f.bytes() * 2, d.bytes());
}

// A table of a constant (a zero-length move) is that constant exactly, with zero derivatives.
TEST(PhaseTable, ConstantFunctionIsExact) {
  for (Precision prec : kPrecisions) {
    for (Interp interp : kOrders) {
      const PhaseTable t({.size = 64, .interp = interp, .precision = prec}, [](double) {
        return PhaseExact{0.125, 0, 0};
      });
      for (int i = 0; i < 1000; ++i) {
        const PhaseSample s = t.at(Phase{i - 500, 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(i)});
        EXPECT_EQ(s.value, 0.125);
        EXPECT_EQ(s.d1, 0.0);
        EXPECT_EQ(s.d2, 0.0);
      }
    }
  }
}

TEST(PhaseTable, AnySizeNotOnlyPowersOfTwo) {
  const PhaseTable t = table(1000, Interp::kCubic);
  for (int k = 0; k < 1000; k += 37) {
    const double p = kTwoPi * k / 1000.0;
    EXPECT_NEAR(t.at(p).value, wave(p).value, 1e-13) << k;
  }
  EXPECT_LT(errors(t, wave).value, 1e-9);
}

TEST(PhaseTable, BytesFollowOrderAndPrecision) {
  EXPECT_EQ(table(256, Interp::kLinear).bytes(), 257u * 1 * 8);
  EXPECT_EQ(table(256, Interp::kCubic).bytes(), 257u * 2 * 8);
  EXPECT_EQ(table(256, Interp::kQuintic, Precision::kFloat).bytes(), 257u * 3 * 4);
}

TEST(PhaseTable, RejectsBadSpecsNamingTheValue) {
  const auto message = [](const TableSpec& s, PhaseExact (*f)(double)) -> std::string {
    try {
      PhaseTable t(s, f);
    } catch (const MotionError& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({.size = 3}, wave).find("size 3"), std::string::npos);
  EXPECT_NE(message({.size = PhaseTable::kMaxSize + 1}, wave).find("must be between 4"), std::string::npos);
  EXPECT_NE(message({.size = 64, .rise = NAN}, wave).find("rise"), std::string::npos);
  EXPECT_NE(message({.size = 64},
                    [](double p) {
                      return PhaseExact{p > 3.0 ? NAN : 0.0, 0, 0};
                    })
                .find("not finite"),
            std::string::npos);
}

// The skeleton's constructor (value and slope, periodic) still builds a cubic double table.
TEST(PhaseTable, SkeletonFormIsCubicDouble) {
  const PhaseTable t(128, [](double p) { return PhaseTable::Exact{wave(p).value, wave(p).d1}; });
  EXPECT_EQ(t.spec().interp, Interp::kCubic);
  EXPECT_EQ(t.spec().precision, Precision::kDouble);
  EXPECT_NEAR(errors(t, wave).value, errors(table(128, Interp::kCubic), wave).value, 1e-15);
}
