// Söylemez slider-crank synthesis: thesis Tables 4.2 and 4.3 digit for digit, the optimum against
// the thesis' cubic and a brute-force search, every design checked by forward analysis, and the
// hard cases φ → 180° (b unbounded), φ = 180° (error) and φ → 90° (μ_min → 0 like x^1.5).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/slider_crank.hpp"
#include "motion_error.hpp"
#include "table_rows.hpp"
#include "thesis_tables.hpp"

namespace {

using loom::test::code_of_call;
using loom::test::message_of;

using loom::motion::deg;
using loom::motion::ErrorCode;
using loom::motion::kDesignChangePoint;
using loom::motion::kPi;
using loom::motion::MotionError;
using loom::motion::rad;
using loom::motion::SliderCrankDesign;
using loom::motion::soylemez_slider_crank;

// Forward check: the synthesised mechanism's own stroke and crank rotation.
void expect_forward_matches(const SliderCrankDesign& d, double stroke, double phi) {
  const auto dc = loom::motion::slider_dead_centres(d.mechanism);
  EXPECT_NEAR(dc.stroke / stroke, 1.0, 1e-9) << "phi " << deg(phi);
  EXPECT_NEAR(dc.phi_fold_to_extend_rad, phi, 1e-9) << "phi " << deg(phi);
  EXPECT_NEAR(dc.mu_min_rad, d.mu_min_rad, 1e-9) << "phi " << deg(phi);
  EXPECT_GT(d.mechanism.offset, 0.0);
}

TEST(Soylemez, Table42EveryPrintedDigit) {
  int rows = 0;
  for (const auto& row : loom::test::table_rows(loom::test::kTable42)) {
    ASSERT_EQ(row.size(), 7u);
    const double phi_deg = std::stod(row[0]);
    if (phi_deg == 180.0) continue;  // the degenerate row: see Phi180IsAnErrorWithTheRightLimits
    const SliderCrankDesign d = soylemez_slider_crank(1.0, rad(phi_deg));
    const double mu = deg(d.mu_min_rad);
    EXPECT_EQ(loom::test::fixed(d.mechanism.crank, 6), row[1]) << "phi " << phi_deg;
    EXPECT_EQ(loom::test::fixed(d.mechanism.coupler, 6), row[2]) << "phi " << phi_deg;
    EXPECT_EQ(loom::test::fixed(d.mechanism.offset, 6), row[3]) << "phi " << phi_deg;
    EXPECT_EQ(loom::test::fixed(mu, 2), row[4]) << "phi " << phi_deg;
    EXPECT_EQ(loom::test::fixed(90.0 - mu, 2), row[5]) << "phi " << phi_deg;
    EXPECT_EQ(loom::test::fixed(d.lambda, 4), row[6]) << "phi " << phi_deg;
    ++rows;
  }
  EXPECT_EQ(rows, 90);  // φ = 90…179
}

TEST(Soylemez, Table43TwelveCentimetreStroke) {
  for (const auto& col : loom::test::kTable43) {
    const SliderCrankDesign d = soylemez_slider_crank(12.0, rad(col.phi_deg));
    const SliderCrankDesign unit = soylemez_slider_crank(1.0, rad(col.phi_deg));
    const double ours[3] = {d.mechanism.crank, d.mechanism.coupler, d.mechanism.offset};
    const double unit_len[3] = {unit.mechanism.crank, unit.mechanism.coupler, unit.mechanism.offset};
    const char* printed[3] = {col.a_cm, col.b_cm, col.c_cm};
    for (int i = 0; i < 3; ++i) {
      // The thesis scaled Table 4.2's 6-decimal values by 12, so the print carries up to
      // 12 × 0.5e-6 = 6e-6 cm of rounding: the exact design agrees within that ...
      EXPECT_NEAR(ours[i], std::stod(printed[i]), 6e-6) << "phi " << col.phi_deg << " link " << i;
      // ... and the thesis' own procedure reproduces every printed digit.
      const double thesis = 12.0 * std::round(unit_len[i] * 1e6) / 1e6;
      EXPECT_TRUE(loom::test::same_at_decimals(thesis, printed[i], 6))
          << "phi " << col.phi_deg << " link " << i << ": " << thesis << " vs " << printed[i];
    }
    EXPECT_TRUE(loom::test::same_at_decimals(deg(d.mu_min_rad), col.mu_min_deg, 2));
    // φ = 90° (λ = 1) is the change-point design: flagged, its crank rotation is degenerate.
    if (d.flags == 0) expect_forward_matches(d, 12.0, rad(col.phi_deg));
  }
}

TEST(Soylemez, LambdaOptSolvesTheThesisCubicAndMaximisesMuMin) {
  for (double phi_deg = 91.0; phi_deg <= 179.5; phi_deg += 0.5) {
    const double phi = rad(phi_deg);
    const double lam = loom::motion::soylemez_lambda_opt(phi);
    // Eq. 4.22: t²Q³ − (1 − t²)Q² − (t⁴ + t² + 1)Q + (1 + t²) = 0 with Q = λ²t².
    const double t2 = std::pow(std::tan(0.5 * phi), 2);
    const double Q = lam * lam * t2;
    const double terms[4] = {t2 * Q * Q * Q, (1 - t2) * Q * Q, (t2 * t2 + t2 + 1) * Q, 1 + t2};
    const double residual = terms[0] - terms[1] - terms[2] + terms[3];
    const double size = std::fabs(terms[0]) + std::fabs(terms[1]) + std::fabs(terms[2]) + terms[3];
    EXPECT_LT(std::fabs(residual), 1e-13 * size) << "phi " << phi_deg;

    // Brute force over the feasible λ: nothing beats λ_opt.
    const auto lb = loom::motion::soylemez_lambda_bounds(phi);
    const double best = soylemez_slider_crank(1.0, phi).mu_min_rad;
    for (int i = 1; i < 400; ++i) {
      const double l = lb.lower + (lb.upper - lb.lower) * i / 400.0;
      EXPECT_LE(soylemez_slider_crank(1.0, phi, l).mu_min_rad, best + 1e-12)
          << "phi " << phi_deg << " lambda " << l;
    }
  }
}

TEST(Soylemez, EveryDesignPassesTheForwardCheck) {
  for (double phi_deg = 90.5; phi_deg < 180.0; phi_deg += 0.25) {
    const double phi = rad(phi_deg);
    expect_forward_matches(soylemez_slider_crank(3.5, phi), 3.5, phi);
    const auto lb = loom::motion::soylemez_lambda_bounds(phi);
    for (double f : {0.01, 0.3, 0.7, 0.99}) {
      const double l = lb.lower + f * (lb.upper - lb.lower);
      const SliderCrankDesign d = soylemez_slider_crank(0.12, phi, l);
      EXPECT_NEAR(d.mechanism.crank / d.mechanism.coupler, l, 1e-14);
      expect_forward_matches(d, 0.12, phi);
    }
  }
}

TEST(Soylemez, PhiToward180StaysAccurate) {
  // b = stroke·(1 − ε/8 + …)/√(2ε) with ε = π − φ (the exact difference of the doubles); the
  // forward check resolves ε itself to 1e-9 relative.
  double previous_b = 0.0;
  for (int k = 2; k <= 13; ++k) {
    const double phi = kPi - std::pow(10.0, -k);
    const double eps = kPi - phi;
    const SliderCrankDesign d = soylemez_slider_crank(1.0, phi);
    ASSERT_TRUE(std::isfinite(d.mechanism.coupler) && std::isfinite(d.mechanism.crank) &&
                std::isfinite(d.mechanism.offset) && std::isfinite(d.mu_min_rad));
    EXPECT_NEAR(d.mechanism.coupler * std::sqrt(2.0 * eps), 1.0, 2.0 * eps + 1e-12) << "eps " << eps;
    EXPECT_GT(d.mechanism.coupler, previous_b);
    previous_b = d.mechanism.coupler;
    const auto dc = loom::motion::slider_dead_centres(d.mechanism);
    EXPECT_NEAR(dc.stroke, 1.0, 1e-9) << "eps " << eps;
    EXPECT_NEAR(dc.phi_half_difference_rad / (kPi - phi), 1.0, 1e-9) << "eps " << eps;
    // Limits of the 180° row: a → 0.5, c → +0.5 (the print's −0.5 has the wrong sign), μ_min → 90°.
    EXPECT_NEAR(d.mechanism.crank, 0.5, 2.0 * std::sqrt(eps));
    EXPECT_NEAR(d.mechanism.offset, 0.5, 2.0 * std::sqrt(eps));
    EXPECT_NEAR(deg(d.mu_min_rad), 90.0, 100.0 * std::sqrt(eps));
  }
}

// Hard case A2: φ given in degrees keeps π − φ exact, so the design a hair below 180° is right to full
// relative precision — checked by the forward kinematics of the designed mechanism (its dead centres are ε
// apart, ε computed in long double) — where the radian path loses ulp(π)/ε of ε (1 % at 180° − 1e-12°).
TEST(Soylemez, PhiIn180DegreesMinusATinyBitKeepsItsDigits) {
  for (const double phi_deg : {179.999999, 180.0 - 1e-9, 180.0 - 1e-12}) {
    const long double eps =
        (180.0L - static_cast<long double>(phi_deg)) * 3.141592653589793238462643383279502884L / 180.0L;
    const SliderCrankDesign d = soylemez_slider_crank(1.0, loom::motion::CrankRotation::degrees(phi_deg));
    ASSERT_TRUE(std::isfinite(d.mechanism.coupler) && std::isfinite(d.mu_min_rad)) << phi_deg;
    const auto dc = loom::motion::slider_dead_centres(d.mechanism);
    EXPECT_NEAR(dc.stroke, 1.0, 1e-9) << phi_deg;
    EXPECT_NEAR(static_cast<double>(dc.phi_half_difference_rad / eps), 1.0, 1e-9) << phi_deg;
    EXPECT_NEAR(static_cast<double>(d.mechanism.coupler * std::sqrt(2.0L * eps)), 1.0,
                1e-9 + 2.0 * static_cast<double>(eps))
        << phi_deg;
  }
}

// φ as a person writes it: 180 − φ subtracted in decimal, so "179.999999999999" is 1e-12° from 180° to full
// relative precision (the double nearest the text is 1e-12° ± 0.14 %), and the A2 design at the written φ is
// right to 1e-9 against the closed form of b in long double. Text that is not plain decimal is left to
// `degrees` (nullopt).
TEST(Soylemez, PhiWrittenInDecimalKeepsItsSupplementExact) {
  using loom::motion::CrankRotation;
  const long double d2r = 3.141592653589793238462643383279502884L / 180.0L;
  const struct {
    const char* text;
    long double supplement_deg;
  } cases[] = {{"179.999999999999", 1e-12L},
               {"179.999999", 1e-6L},
               {"90", 90.0L},
               {"180", 0.0L},
               {"180.", 0.0L},
               {".5", 179.5L},
               {"0179.25", 0.75L},
               {"180.000001", -1e-6L},
               {"359.9", -179.9L},
               {"100.125", 79.875L}};
  for (const auto& c : cases) {
    const auto r = CrankRotation::decimal_degrees(c.text);
    ASSERT_TRUE(r.has_value()) << c.text;
    const long double want = c.supplement_deg * d2r;
    if (want == 0.0L) {
      EXPECT_EQ(r->supplement_rad, 0.0) << c.text;
    } else {
      EXPECT_NEAR(static_cast<double>(r->supplement_rad / want), 1.0, 4e-16) << c.text;
    }
    EXPECT_EQ(r->phi_rad, loom::motion::rad(std::strtod(c.text, nullptr))) << c.text;
  }
  for (const char* bad : {"", ".", "1e2", "-5", "+5", "nan", "inf", "1.2.3", " 90", "90 ", "0x10"}) {
    EXPECT_FALSE(CrankRotation::decimal_degrees(bad).has_value()) << "'" << bad << "'";
  }
  EXPECT_FALSE(CrankRotation::decimal_degrees(std::string(61, '1')).has_value());

  const long double eps = 1e-12L * d2r;  // hard case A2 as written: 180° − 1e-12°
  const long double k = std::sin(eps / 2.0L), s = std::cos(eps / 2.0L), w = std::sqrt(4.0L + k * k);
  const long double b = 0.5L / std::sqrt(k * k + 2.0L * k / (s * s * (w + k)) * s * s);
  const SliderCrankDesign d = soylemez_slider_crank(1.0, *CrankRotation::decimal_degrees("179.999999999999"));
  EXPECT_NEAR(static_cast<double>(d.mechanism.coupler / b), 1.0, 1e-9);
  const SliderCrankDesign from_double = soylemez_slider_crank(1.0, CrankRotation::degrees(179.999999999999));
  EXPECT_GT(std::abs(static_cast<double>(from_double.mechanism.coupler / b) - 1.0), 1e-4);  // why it exists
}

TEST(Soylemez, Phi180IsAnErrorWithTheRightLimits) {
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(1.0, kPi); }), ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(1.0, rad(180.0)); }), ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(1.0, std::nextafter(kPi, 0.0)); }),
            ErrorCode::kInvalidInput);  // within the 1e-14 rad snap of 180°
  EXPECT_NE(message_of([] { soylemez_slider_crank(1.0, kPi); }).find("phi = 180"), std::string::npos);
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(1.0, rad(181.0)); }), ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(1.0, rad(89.0)); }), ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(1.0, std::nan("")); }), ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(0.0, rad(169.0)); }), ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { soylemez_slider_crank(-1.0, rad(169.0)); }), ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { loom::motion::soylemez_lambda_opt(kPi); }), ErrorCode::kInvalidInput);
}

TEST(Soylemez, Phi90IsTheChangePointWithZeroMuMin) {
  const SliderCrankDesign d = soylemez_slider_crank(1.0, rad(90.0));
  EXPECT_EQ(d.lambda, 1.0);
  EXPECT_NEAR(d.mechanism.crank, 0.5, 1e-15);
  EXPECT_NEAR(d.mechanism.coupler, 0.5, 1e-15);
  EXPECT_EQ(d.mechanism.offset, 0.0);
  EXPECT_EQ(d.mu_min_rad, 0.0);
  EXPECT_TRUE(d.flags & kDesignChangePoint);
  EXPECT_NEAR(loom::motion::slider_dead_centres(d.mechanism).stroke, 1.0, 1e-15);
}

TEST(Soylemez, MuMinNear90GrowsLikeXToTheThreeHalves) {
  // Series of the closed form at φ = 90° + x: 1 − cos μ_min = 4x³/27, so μ_min ≈ √(8/27)·x^1.5.
  // A naive acos((a + c)/b) returns ~1e-8 rad noise here instead of ~1e-11.
  for (int k = 2; k <= 7; ++k) {
    const double x = std::pow(10.0, -k);
    const SliderCrankDesign d = soylemez_slider_crank(1.0, 0.5 * kPi + x);
    const double series = std::sqrt(8.0 / 27.0) * std::pow(x, 1.5);
    EXPECT_NEAR(d.mu_min_rad / series, 1.0, 10.0 * x) << "x " << x;
    EXPECT_FALSE(d.flags & kDesignChangePoint);
  }
}

TEST(Soylemez, GivenLambdaBoundsAndChangePoints) {
  const double phi = rad(169.0);
  const auto lb = loom::motion::soylemez_lambda_bounds(phi);
  EXPECT_NEAR(lb.lower, 1.0 / std::pow(std::tan(0.5 * phi), 2), 1e-15);
  EXPECT_EQ(lb.upper, 1.0);
  for (double l : {lb.lower, lb.upper}) {
    const SliderCrankDesign d = soylemez_slider_crank(1.0, phi, l);
    EXPECT_TRUE(d.flags & kDesignChangePoint) << l;
    EXPECT_EQ(d.mu_min_rad, 0.0);
    // Change point: the coupler spans exactly crank + offset.
    EXPECT_NEAR(d.mechanism.coupler - d.mechanism.crank - d.mechanism.offset, 0.0, 1e-14);
  }
  // Just inside a bound: regular design, small μ_min.
  const SliderCrankDesign inside = soylemez_slider_crank(1.0, phi, lb.lower + 1e-9);
  EXPECT_EQ(inside.flags, 0u);
  EXPECT_GT(inside.mu_min_rad, 0.0);
  EXPECT_LT(inside.mu_min_rad, 1e-3);

  EXPECT_EQ(code_of_call([&] { soylemez_slider_crank(1.0, phi, 1.01); }), ErrorCode::kOutOfBounds);
  EXPECT_EQ(code_of_call([&] { soylemez_slider_crank(1.0, phi, 0.005); }), ErrorCode::kOutOfBounds);
  const std::string msg = message_of([&] { soylemez_slider_crank(1.0, phi, 1.01); });
  EXPECT_NE(msg.find("lambda"), std::string::npos) << msg;
  EXPECT_NE(msg.find(", 1]"), std::string::npos) << msg;
  EXPECT_EQ(code_of_call([&] { soylemez_slider_crank(1.0, phi, std::nan("")); }), ErrorCode::kInvalidInput);
}

TEST(Soylemez, NoNaNOrInfAnywhereInTheDomain) {
  for (int i = 0; i <= 2000; ++i) {
    // From 90° to within 2e-14 rad of 180°, denser near both ends.
    const double u = i / 2000.0;
    const double phi = 0.5 * kPi + (0.5 * kPi - 2e-14) * (0.5 - 0.5 * std::cos(kPi * u));
    const auto check = [&](const SliderCrankDesign& d) {
      EXPECT_TRUE(std::isfinite(d.mechanism.crank) && std::isfinite(d.mechanism.coupler) &&
                  std::isfinite(d.mechanism.offset) && std::isfinite(d.mu_min_rad) && std::isfinite(d.lambda))
          << "phi " << phi;
      EXPECT_GE(d.mu_min_rad, 0.0);
      EXPECT_LE(d.mu_min_rad, 0.5 * kPi);
    };
    check(soylemez_slider_crank(1.0, phi));
    const auto lb = loom::motion::soylemez_lambda_bounds(phi);
    for (double f : {0.0, 1e-12, 0.5, 1.0 - 1e-12, 1.0})
      check(soylemez_slider_crank(1.0, phi, lb.lower + f * (lb.upper - lb.lower)));
  }
}

TEST(Soylemez, TinyAndHugeStrokesScaleExactly) {
  const SliderCrankDesign unit = soylemez_slider_crank(1.0, rad(169.0));
  for (double stroke : {1e-9, 1e-3, 1e3, 1e9}) {
    const SliderCrankDesign d = soylemez_slider_crank(stroke, rad(169.0));
    EXPECT_NEAR(d.mechanism.crank / stroke / unit.mechanism.crank, 1.0, 1e-15);
    EXPECT_NEAR(d.mechanism.coupler / stroke / unit.mechanism.coupler, 1.0, 1e-15);
    EXPECT_NEAR(d.mechanism.offset / stroke / unit.mechanism.offset, 1.0, 1e-15);
    EXPECT_EQ(d.mu_min_rad, unit.mu_min_rad);
    expect_forward_matches(d, stroke, rad(169.0));
  }
}

}  // namespace
