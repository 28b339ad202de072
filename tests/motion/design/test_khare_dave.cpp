// Khare–Dave crank-rocker synthesis: thesis Table 4.8 digit for digit, the β bounds of every case
// (each bound a change point), and every design checked by an independent forward analysis — the
// law of cosines at the two dead centres gives the swing ψ and crank rotation φ actually achieved.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"
#include "loom/motion/errors.hpp"
#include "motion_error.hpp"
#include "table_rows.hpp"
#include "thesis_tables.hpp"

namespace {

using loom::test::code_of_call;
using loom::test::message_of;

using loom::motion::CrankRockerCase;
using loom::motion::CrankRockerDesign;
using loom::motion::deg;
using loom::motion::ErrorCode;
using loom::motion::kDesignChangePoint;
using loom::motion::kDesignNearSpecialCase;
using loom::motion::khare_dave_crank_rocker;
using loom::motion::kNearSpecialCase_rad;
using loom::motion::kPi;
using loom::motion::kTwoPi;
using loom::motion::MotionError;
using loom::motion::rad;

// ---------------------------------------------------------------------------------------------
// Independent forward analysis. Ground A0 = (0,0), B0 = (d,0), coupler point B above the ground
// line. At the extended dead centre |A0B| = a + b and the crank points at B; at the folded one
// |A0B| = b − a and the crank points away from B.
struct Forward {
  double beta;             // crank angle at the extended dead centre
  double phi;              // counter-clockwise crank travel extended → folded
  double psi;              // rocker swing between the dead centres
  double rocker_extended;  // rocker direction B0→B at the extended dead centre, from +x
};

// Law of cosines for the angle opposite side r, in Kahan's half-angle form: the plain acos loses
// half the digits for the thin triangles of small swings (angles near 0 or π).
double angle_opposite(double r, double p, double q) {
  if (p < q) std::swap(p, q);
  const double mu = (q >= r) ? r - (p - q) : q - (p - r);
  return 2.0 * std::atan(std::sqrt(((p - q) + r) * mu / ((p + (q + r)) * ((p - r) + q))));
}

Forward forward(double a, double b, double c, double d) {
  const double le = a + b, lf = b - a;
  const double at_a0_e = angle_opposite(c, le, d);
  const double at_a0_f = angle_opposite(c, lf, d);
  const double at_b0_e = angle_opposite(le, d, c);
  const double at_b0_f = angle_opposite(lf, d, c);
  Forward f{};
  f.beta = at_a0_e;
  f.phi = loom::motion::wrap_two_pi(kPi + at_a0_f - at_a0_e);
  f.psi = at_b0_e - at_b0_f;
  f.rocker_extended = kPi - at_b0_e;
  return f;
}

// Minimum acute transmission angle over a sampled turn (θ = 0 and π are on the grid).
double sampled_mu_min(const CrankRockerDesign& m) {
  double best = kPi;
  for (int i = 0; i <= 20000; ++i) {
    const double th = kTwoPi * i / 20000.0;
    const double dx = m.crank * std::cos(th) - m.ground, dy = m.crank * std::sin(th);
    const double r2 = dx * dx + dy * dy;
    const double cos_mu = (m.coupler * m.coupler + m.rocker * m.rocker - r2) / (2 * m.coupler * m.rocker);
    const double mu = std::acos(std::clamp(cos_mu, -1.0, 1.0));
    best = std::min(best, std::min(mu, kPi - mu));
  }
  return best;
}

// s + l − p − q over the four links (negative: Grashof), and whether the crank is the shortest.
double grashof_excess(const CrankRockerDesign& m) {
  double l[4] = {m.crank, m.coupler, m.rocker, m.ground};
  std::sort(l, l + 4);
  return l[0] + l[3] - l[1] - l[2];
}

void expect_design_achieves(const CrankRockerDesign& m, double psi, double phi, double beta) {
  const Forward f = forward(m.crank, m.coupler, m.rocker, m.ground);
  EXPECT_NEAR(f.psi, psi, 1e-9) << "psi " << deg(psi) << " phi " << deg(phi) << " beta " << deg(beta);
  EXPECT_NEAR(f.phi, phi, 1e-9) << "psi " << deg(psi) << " phi " << deg(phi) << " beta " << deg(beta);
  EXPECT_NEAR(f.beta, beta, 1e-9) << "psi " << deg(psi) << " phi " << deg(phi) << " beta " << deg(beta);
  EXPECT_NEAR(m.rocker_extended_rad, f.rocker_extended, 1e-9);
  EXPECT_NEAR(m.crank_folded_rad, loom::motion::wrap_two_pi(beta + phi), 1e-12);
  // A true crank-rocker: Grashof with the crank shortest.
  EXPECT_LT(grashof_excess(m), 0.0);
  EXPECT_LE(m.crank, std::min({m.coupler, m.rocker, m.ground}));
  EXPECT_NEAR(m.mu_min_rad, sampled_mu_min(m), 1e-9);
}

// (ψ, φ) pairs covering every case, away from the special values.
std::vector<std::pair<double, double>> sweep_cases() {
  std::vector<std::pair<double, double>> out;
  for (double psi_deg : {5.0, 30.0, 60.0, 90.0, 120.0, 150.0, 175.0}) {
    const double lo = 90.0 + psi_deg / 2, hi = 270.0 + psi_deg / 2;
    for (int i = 1; i < 24; ++i) {
      const double phi_deg = lo + (hi - lo) * i / 24.0;
      if (std::fabs(phi_deg - 180.0) < 0.5 || std::fabs(phi_deg - 180.0 - psi_deg) < 0.5) continue;
      out.emplace_back(psi_deg, phi_deg);
    }
    out.emplace_back(psi_deg, 180.0);
  }
  return out;
}

TEST(KhareDave, Table48EveryPrintedDigit) {
  int rows = 0;
  for (const auto& row : loom::test::table_rows(loom::test::kTable48)) {
    ASSERT_EQ(row.size(), 5u);
    const double beta_deg = std::stod(row[0]);
    if (beta_deg == 0.0) {
      // Printed μ_min = ∞ (eq. 4.43 read as 0/0), a = c = 0: the lower bound of β is the null crank,
      // not a mechanism — a typed error that gives the limit μ_min → 90° − ψ/2 = 75° instead.
      EXPECT_EQ(row[4], "∞");
      try {
        khare_dave_crank_rocker(rad(30.0), rad(180.0), 0.0);
        ADD_FAILURE() << "beta = 0 at phi = 180 must throw";
      } catch (const loom::motion::MotionError& e) {
        EXPECT_EQ(e.code(), loom::motion::ErrorCode::kOutOfBounds);
        EXPECT_NE(std::string(e.what()).find("null crank"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("mu_min -> 75 deg"), std::string::npos) << e.what();
      }
      ++rows;
      continue;
    }
    const CrankRockerDesign d = khare_dave_crank_rocker(rad(30.0), rad(180.0), rad(beta_deg));
    EXPECT_EQ(d.design_case, CrankRockerCase::kPhi180);
    EXPECT_TRUE(loom::test::same_at_decimals(d.crank, row[1], 6)) << "beta " << beta_deg << " a " << d.crank;
    EXPECT_TRUE(loom::test::same_at_decimals(d.coupler, row[2], 6))
        << "beta " << beta_deg << " b " << d.coupler;
    EXPECT_TRUE(loom::test::same_at_decimals(d.rocker, row[3], 6))
        << "beta " << beta_deg << " c " << d.rocker;
    EXPECT_TRUE(loom::test::same_at_decimals(deg(d.mu_min_rad), row[4], 2))
        << "beta " << beta_deg << " mu " << deg(d.mu_min_rad);
    EXPECT_EQ(d.flags, beta_deg == 75.0 ? kDesignChangePoint : 0u) << "beta " << beta_deg;
    // Eq. 4.43: cos μ_min = sin(ψ/2) / cos β for the centric linkage.
    if (beta_deg < 75.0) {
      EXPECT_NEAR(std::cos(d.mu_min_rad), std::sin(rad(15.0)) / std::cos(rad(beta_deg)), 1e-13);
      expect_design_achieves(d, rad(30.0), kPi, rad(beta_deg));
    }
    ++rows;
  }
  EXPECT_EQ(rows, 76);
}

TEST(KhareDave, NullCrankRowIsTheLimitOfTheCentricFamily) {
  // Approaching β = 0 at φ = 180° the linkage shrinks to a = c = 0, b = 1 while μ_min rises to
  // 90° − ψ/2 (eq. 4.43): the β = 0 row is a limit, reported flagged with μ_min = 0.
  for (double beta : {1e-3, 1e-6, 1e-9}) {
    const CrankRockerDesign d = khare_dave_crank_rocker(rad(30.0), kPi, beta);
    EXPECT_EQ(d.flags, 0u);
    EXPECT_NEAR(d.crank, std::tan(rad(15.0)) * std::sin(beta), 1e-16);  // eq. 4.41
    EXPECT_NEAR(deg(d.mu_min_rad), 75.0, 1e-3);
  }
  EXPECT_THROW(khare_dave_crank_rocker(rad(30.0), kPi, 0.0), loom::motion::MotionError);
}

// Within ~1e-6° of φ = 180° + ψ the general formula's b and c grow like 1/|φ − 180° − ψ| (≈ 1e7 at
// 1e-6°): the limit depends on the side it is approached from and is not the case-III linkage, so the
// design is flagged. On the special case itself (within rounding) it is case III, unflagged.
TEST(KhareDave, NearTheSpecialCaseIsFlaggedNotSilent) {
  // β = 60° below the special case (β ∈ [0, 75°]), 100° above it (β ∈ [75°, 360° − φ]).
  for (double off_deg : {-1e-6, 1e-6, -1e-5, 3e-5}) {
    const double phi = rad(210.0 + off_deg);
    const CrankRockerDesign d = khare_dave_crank_rocker(rad(30.0), phi, rad(off_deg < 0.0 ? 60.0 : 100.0));
    EXPECT_NE(d.design_case, CrankRockerCase::kPhi180PlusPsi) << off_deg;
    EXPECT_TRUE(d.flags & kDesignNearSpecialCase) << off_deg;
    EXPECT_GT(d.coupler, 1e4) << off_deg;  // the growth the flag warns about
    EXPECT_TRUE(std::isfinite(d.coupler) && std::isfinite(d.rocker));
  }
  const CrankRockerDesign special = khare_dave_crank_rocker(rad(30.0), rad(210.0), rad(75.0));
  EXPECT_EQ(special.design_case, CrankRockerCase::kPhi180PlusPsi);
  EXPECT_EQ(special.flags & kDesignNearSpecialCase, 0u);
  // Away from it: no flag.
  for (double phi_deg : {200.0, 209.9, 210.1, 220.0}) {
    const double beta_deg = phi_deg < 210.0 ? 60.0 : 100.0;
    EXPECT_EQ(khare_dave_crank_rocker(rad(30.0), rad(phi_deg), rad(beta_deg)).flags & kDesignNearSpecialCase,
              0u)
        << phi_deg;
  }
  EXPECT_NEAR(deg(kNearSpecialCase_rad), 1e-4, 1e-18);
}

TEST(KhareDave, ThesisGraphicalSolutionForBeta48) {
  // §4.5.2 b, case study 3: ground 10 cm, ψ = 30°, φ = 180°, β = 48° → crank 1.9913,
  // coupler 6.6913, rocker 7.6936 cm.
  const CrankRockerDesign d = khare_dave_crank_rocker(rad(30.0), kPi, rad(48.0), 10.0);
  EXPECT_NEAR(d.crank, 1.9913, 5e-5);
  EXPECT_NEAR(d.coupler, 6.6913, 5e-5);
  EXPECT_NEAR(d.rocker, 7.6936, 5e-5);
  expect_design_achieves(d, rad(30.0), kPi, rad(48.0));
}

TEST(KhareDave, AgreesWithTheThesisClosedForm) {
  // Eqs. 4.27 and 4.29 as printed (they are right), evaluated directly.
  for (const auto& [psi_deg, phi_deg] : sweep_cases()) {
    const double psi = rad(psi_deg), phi = rad(phi_deg);
    const auto bounds = loom::motion::khare_dave_beta_bounds(psi, phi);
    for (double f : {0.1, 0.5, 0.9}) {
      const double beta = bounds.lower_rad + f * (bounds.upper_rad - bounds.lower_rad);
      const double a1 = psi / 2, a2 = phi / 2 - psi / 2, b1 = phi / 2 + beta;
      const double a = -std::sin(a1) * std::cos(b1) / std::sin(a2);
      const double b = std::sin(a1) * std::sin(b1) / std::cos(a2);
      const double c = std::sqrt((a + b) * (a + b) + 1 - 2 * (a + b) * std::cos(beta));
      const CrankRockerDesign d = khare_dave_crank_rocker(psi, phi, beta);
      EXPECT_NEAR(d.crank / a, 1.0, 1e-12) << psi_deg << " " << phi_deg << " " << deg(beta);
      EXPECT_NEAR(d.coupler / b, 1.0, 1e-12) << psi_deg << " " << phi_deg << " " << deg(beta);
      EXPECT_NEAR(d.rocker / c, 1.0, 1e-12) << psi_deg << " " << phi_deg << " " << deg(beta);
    }
  }
}

TEST(KhareDave, EveryDesignPassesTheForwardCheck) {
  for (const auto& [psi_deg, phi_deg] : sweep_cases()) {
    const double psi = rad(psi_deg), phi = rad(phi_deg);
    const auto bounds = loom::motion::khare_dave_beta_bounds(psi, phi);
    for (double f : {0.02, 0.25, 0.5, 0.75, 0.98}) {
      const double beta = bounds.lower_rad + f * (bounds.upper_rad - bounds.lower_rad);
      const CrankRockerDesign d = khare_dave_crank_rocker(psi, phi, beta, 0.213);
      EXPECT_EQ(d.flags, 0u);
      expect_design_achieves(d, psi, phi, beta);
    }
  }
}

TEST(KhareDave, BoundsOfEveryCase) {
  struct Case {
    double psi, phi, lower, upper;
    CrankRockerCase kind;
  };
  const Case cases[] = {
      {30, 120, 60, 75, CrankRockerCase::kPhiBelow180},    // thesis case study 1
      {30, 160, 20, 75, CrankRockerCase::kPhiBelow180},    // case study 2 (the print's "60" is a typo)
      {30, 180, 0, 75, CrankRockerCase::kPhi180},          // case study 3
      {30, 200, 0, 75, CrankRockerCase::kPhiAbove180},     // case study 4
      {30, 210, 75, 75, CrankRockerCase::kPhi180PlusPsi},  // case study 5
      {30, 220, 75, 140, CrankRockerCase::kPhiBeyond180PlusPsi},
      {60, 250, 60, 110, CrankRockerCase::kPhiBeyond180PlusPsi},
  };
  for (const Case& c : cases) {
    const auto b = loom::motion::khare_dave_beta_bounds(rad(c.psi), rad(c.phi));
    EXPECT_NEAR(deg(b.lower_rad), c.lower, 1e-12) << c.psi << " " << c.phi;
    EXPECT_NEAR(deg(b.upper_rad), c.upper, 1e-12) << c.psi << " " << c.phi;
    EXPECT_EQ(b.design_case, c.kind) << c.psi << " " << c.phi;
  }
}

TEST(KhareDave, BetaAtABoundIsAFlaggedChangePoint) {
  for (const auto& [psi_deg, phi_deg] : sweep_cases()) {
    const double psi = rad(psi_deg), phi = rad(phi_deg);
    const auto bounds = loom::motion::khare_dave_beta_bounds(psi, phi);
    for (double beta : {bounds.lower_rad, bounds.upper_rad}) {
      if (bounds.design_case == CrankRockerCase::kPhi180 && beta == 0.0) {
        // The null crank: not a mechanism (tested above); μ_min tends to 90° − ψ/2 next to it.
        EXPECT_THROW(khare_dave_crank_rocker(psi, phi, beta), loom::motion::MotionError);
        continue;
      }
      const CrankRockerDesign d = khare_dave_crank_rocker(psi, phi, beta);
      EXPECT_TRUE(d.flags & kDesignChangePoint) << psi_deg << " " << phi_deg << " " << deg(beta);
      EXPECT_EQ(d.mu_min_rad, 0.0);
      EXPECT_NEAR(grashof_excess(d), 0.0, 1e-12 * (1.0 + d.coupler + d.rocker))
          << psi_deg << " " << phi_deg << " " << deg(beta);
      EXPECT_TRUE(std::isfinite(d.crank) && std::isfinite(d.coupler) && std::isfinite(d.rocker));
      // Just inside the bound the linkage is regular with a small positive μ_min.
      const double inside = beta == bounds.lower_rad ? beta + 1e-7 : beta - 1e-7;
      const CrankRockerDesign near = khare_dave_crank_rocker(psi, phi, inside);
      EXPECT_EQ(near.flags, 0u);
      EXPECT_GT(near.mu_min_rad, 0.0);
      EXPECT_LT(near.mu_min_rad, 0.01);
    }
  }
}

TEST(KhareDave, BetaOutsideTheBoundsIsOutOfBoundsNamingThem) {
  EXPECT_EQ(code_of_call([] { khare_dave_crank_rocker(rad(30.0), rad(120.0), rad(59.0)); }),
            ErrorCode::kOutOfBounds);
  EXPECT_EQ(code_of_call([] { khare_dave_crank_rocker(rad(30.0), rad(120.0), rad(75.5)); }),
            ErrorCode::kOutOfBounds);
  EXPECT_EQ(code_of_call([] { khare_dave_crank_rocker(rad(30.0), rad(210.0), rad(70.0)); }),
            ErrorCode::kOutOfBounds);
  const std::string msg = message_of([] { khare_dave_crank_rocker(rad(30.0), rad(120.0), rad(80.0)); });
  EXPECT_NE(msg.find("beta = 80"), std::string::npos) << msg;
  EXPECT_NE(msg.find("[60, 75]"), std::string::npos) << msg;
  EXPECT_EQ(code_of_call([] { khare_dave_crank_rocker(rad(30.0), rad(120.0), std::nan("")); }),
            ErrorCode::kInvalidInput);
}

TEST(KhareDave, ImpossibleSwingOrRotationIsInvalidInput) {
  EXPECT_EQ(code_of_call([] { loom::motion::khare_dave_beta_bounds(rad(30.0), rad(105.0)); }),
            ErrorCode::kInvalidInput);  // φ must exceed 90° + ψ/2
  EXPECT_EQ(code_of_call([] { loom::motion::khare_dave_beta_bounds(rad(30.0), rad(285.0)); }),
            ErrorCode::kInvalidInput);  // and stay below 270° + ψ/2
  EXPECT_EQ(code_of_call([] { loom::motion::khare_dave_beta_bounds(0.0, rad(180.0)); }),
            ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { loom::motion::khare_dave_beta_bounds(kPi, rad(180.0)); }),
            ErrorCode::kInvalidInput);
  EXPECT_EQ(code_of_call([] { khare_dave_crank_rocker(rad(30.0), rad(180.0), rad(40.0), 0.0); }),
            ErrorCode::kInvalidInput);
  const std::string msg = message_of([] { loom::motion::khare_dave_beta_bounds(rad(30.0), rad(100.0)); });
  EXPECT_NE(msg.find("phi"), std::string::npos);
}

TEST(KhareDave, Phi180PlusPsiIsTheSpecialCaseNotTheGeneralFormula) {
  for (double psi_deg : {10.0, 30.0, 60.0, 90.0, 150.0}) {
    const double psi = rad(psi_deg);
    const double phi = rad(180.0 + psi_deg);  // off π + ψ by rounding: must still be case III
    const CrankRockerDesign d = khare_dave_crank_rocker(psi, phi, rad(90.0 - psi_deg / 2));
    EXPECT_EQ(d.design_case, CrankRockerCase::kPhi180PlusPsi);
    // Eqs. 4.37–4.39.
    const double a = std::sin(psi / 2);
    EXPECT_NEAR(d.crank, a, 1e-15);
    EXPECT_NEAR(d.coupler, std::sqrt(a * (1 + a)), 1e-15);
    EXPECT_NEAR(d.rocker, std::sqrt(1 + a), 1e-15);
    EXPECT_NEAR(std::cos(d.mu_min_rad), 2 * std::sqrt(a) / (1 + a), 1e-14);
    EXPECT_EQ(d.flags, 0u);
    expect_design_achieves(d, psi, kPi + psi, rad(90.0 - psi_deg / 2));
    // β is fixed for this case.
    EXPECT_EQ(code_of_call([&] { khare_dave_crank_rocker(psi, phi, rad(80.0 - psi_deg / 2)); }),
              ErrorCode::kOutOfBounds);
    // Every member of the family (coupler b = a/λ) achieves (ψ, φ); the thesis' member is the best.
    for (double lam : {0.05, 0.2, 0.5, 0.8, 0.95}) {
      const CrankRockerDesign m = loom::motion::khare_dave_for_ratio(psi, phi, lam);
      expect_design_achieves(m, psi, kPi + psi, rad(90.0 - psi_deg / 2));
      EXPECT_LE(m.mu_min_rad, d.mu_min_rad + 1e-15);
    }
    EXPECT_TRUE(loom::motion::khare_dave_for_ratio(psi, phi, 1.0).flags & kDesignChangePoint);
    EXPECT_EQ(code_of_call([&] { loom::motion::khare_dave_for_ratio(psi, phi, 1.2); }),
              ErrorCode::kOutOfBounds);
    // Best β returns the same design.
    EXPECT_NEAR(loom::motion::khare_dave_best_beta(psi, phi).coupler, d.coupler, 1e-15);
  }
}

TEST(KhareDave, NearTheSpecialCaseStaysFiniteAndCorrect) {
  // A hair away from φ = π + ψ the general formula holds with a long coupler near the fixed β.
  const double psi = rad(30.0);
  for (double off : {1e-3, -1e-3, 1e-5, -1e-5}) {
    const double phi = kPi + psi + off;
    const auto b = loom::motion::khare_dave_beta_bounds(psi, phi);
    const double beta = 0.5 * (b.lower_rad + b.upper_rad);
    const CrankRockerDesign d = khare_dave_crank_rocker(psi, phi, beta);
    EXPECT_TRUE(std::isfinite(d.coupler) && std::isfinite(d.rocker) && std::isfinite(d.mu_min_rad));
    const Forward f = forward(d.crank, d.coupler, d.rocker, d.ground);
    EXPECT_NEAR(f.psi, psi, 1e-7) << off;
    EXPECT_NEAR(f.phi, phi, 1e-7) << off;
  }
}

TEST(KhareDave, BestBetaMaximisesMuMin) {
  for (const auto& [psi_deg, phi_deg] : sweep_cases()) {
    if (phi_deg == 180.0) continue;
    const double psi = rad(psi_deg), phi = rad(phi_deg);
    const CrankRockerDesign best = loom::motion::khare_dave_best_beta(psi, phi);
    EXPECT_EQ(best.flags, 0u);
    expect_design_achieves(best, psi, phi, best.beta_rad);
    const auto bounds = loom::motion::khare_dave_beta_bounds(psi, phi);
    for (int i = 1; i < 1000; ++i) {
      const double beta = bounds.lower_rad + (bounds.upper_rad - bounds.lower_rad) * i / 1000.0;
      EXPECT_LE(khare_dave_crank_rocker(psi, phi, beta).mu_min_rad, best.mu_min_rad + 1e-12)
          << psi_deg << " " << phi_deg << " beta " << deg(beta);
    }
  }
  // The thesis read β from Alt charts to about a degree: 70° (φ = 120°), 55° (160°), 67° (200°).
  EXPECT_NEAR(deg(loom::motion::khare_dave_best_beta(rad(30.0), rad(120.0)).beta_rad), 70.0, 1.0);
  EXPECT_NEAR(deg(loom::motion::khare_dave_best_beta(rad(30.0), rad(160.0)).beta_rad), 55.0, 1.0);
  EXPECT_NEAR(deg(loom::motion::khare_dave_best_beta(rad(30.0), rad(200.0)).beta_rad), 67.0, 1.0);
}

TEST(KhareDave, Phi180HasNoBestBetaButARatioPicksOne) {
  EXPECT_EQ(code_of_call([] { loom::motion::khare_dave_best_beta(rad(30.0), kPi); }),
            ErrorCode::kOutOfBounds);
  // The thesis' β = 48° is the largest integer β with a/b ≤ 0.3 (sley eccentricity criterion).
  const CrankRockerDesign d = loom::motion::khare_dave_for_ratio(rad(30.0), kPi, 0.3);
  EXPECT_NEAR(d.crank / d.coupler, 0.3, 1e-14);
  EXPECT_NEAR(deg(d.beta_rad), deg(std::atan(0.3 / std::tan(rad(15.0)))), 1e-12);
  EXPECT_GT(deg(d.beta_rad), 48.0);
  EXPECT_LT(deg(d.beta_rad), 49.0);
  for (const auto& [psi_deg, phi_deg] : sweep_cases()) {
    const double psi = rad(psi_deg), phi = rad(phi_deg);
    const auto bounds = loom::motion::khare_dave_beta_bounds(psi, phi);
    const double beta = bounds.lower_rad + 0.37 * (bounds.upper_rad - bounds.lower_rad);
    const CrankRockerDesign ref = khare_dave_crank_rocker(psi, phi, beta);
    const CrankRockerDesign back = loom::motion::khare_dave_for_ratio(psi, phi, ref.crank / ref.coupler);
    EXPECT_NEAR(back.beta_rad, beta, 1e-9) << psi_deg << " " << phi_deg;
  }
  EXPECT_EQ(code_of_call([] { loom::motion::khare_dave_for_ratio(rad(30.0), rad(120.0), 2.0); }),
            ErrorCode::kOutOfBounds);
}

TEST(KhareDave, NoNaNOrInfAnywhereInTheDomain) {
  for (int ip = 1; ip < 60; ++ip) {
    const double psi = kPi * ip / 60.0;
    const double lo = 0.5 * kPi + 0.5 * psi, hi = 1.5 * kPi + 0.5 * psi;
    for (int jp = 1; jp < 80; ++jp) {
      double phi = lo + (hi - lo) * jp / 80.0;
      if (jp == 40) phi = kPi + psi;  // the special case itself
      const auto bounds = loom::motion::khare_dave_beta_bounds(psi, phi);
      for (int k = 0; k <= 10; ++k) {
        const double beta = bounds.lower_rad + (bounds.upper_rad - bounds.lower_rad) * k / 10.0;
        if (bounds.design_case == CrankRockerCase::kPhi180 && beta == 0.0) {
          EXPECT_THROW(khare_dave_crank_rocker(psi, phi, beta, 0.2),
                       loom::motion::MotionError);  // null crank
          continue;
        }
        const CrankRockerDesign d = khare_dave_crank_rocker(psi, phi, beta, 0.2);
        const double v[] = {d.crank,
                            d.coupler,
                            d.rocker,
                            d.mu_min_rad,
                            d.crank_extended_rad,
                            d.crank_folded_rad,
                            d.rocker_extended_rad,
                            d.rocker_folded_rad};
        for (double x : v) ASSERT_TRUE(std::isfinite(x)) << deg(psi) << " " << deg(phi) << " " << deg(beta);
        ASSERT_GE(d.mu_min_rad, 0.0);
        ASSERT_LE(d.mu_min_rad, 0.5 * kPi);
      }
    }
  }
}

TEST(KhareDave, TinyAndHugeGroundsAndSwings) {
  const CrankRockerDesign unit = khare_dave_crank_rocker(rad(30.0), rad(160.0), rad(50.0));
  for (double ground : {1e-9, 1e-3, 1e3, 1e9}) {
    const CrankRockerDesign d = khare_dave_crank_rocker(rad(30.0), rad(160.0), rad(50.0), ground);
    EXPECT_NEAR(d.crank / ground / unit.crank, 1.0, 1e-15);
    EXPECT_NEAR(d.coupler / ground / unit.coupler, 1.0, 1e-15);
    EXPECT_NEAR(d.rocker / ground / unit.rocker, 1.0, 1e-15);
    EXPECT_EQ(d.mu_min_rad, unit.mu_min_rad);
  }
  // A swing of a micro-radian: the crank is ~ψ/2 long; the design still closes exactly.
  for (double psi : {1e-6, 1e-3, kPi - 1e-3}) {
    for (double phi : {0.5 * kPi + 0.5 * psi + 0.3, kPi, kPi + 0.5 * psi}) {
      const auto bounds = loom::motion::khare_dave_beta_bounds(psi, phi);
      const double beta = 0.5 * (bounds.lower_rad + bounds.upper_rad);
      const CrankRockerDesign d = khare_dave_crank_rocker(psi, phi, beta);
      const Forward f = forward(d.crank, d.coupler, d.rocker, d.ground);
      // A crank this small pins its dead-centre angles only to ~ulp(rocker)/(b − a).
      const double tol = 1e-9 + 1e-15 / (d.coupler - d.crank);
      EXPECT_NEAR(f.psi / psi, 1.0, 1e-6) << psi << " " << phi;
      EXPECT_NEAR(f.phi, phi, tol) << psi << " " << phi;
      EXPECT_TRUE(std::isfinite(d.mu_min_rad));
    }
  }
}

}  // namespace

// φ → 180°: the designs depend on the supplement s = 180° − φ, which a degree input gives exactly
// (Sterbenz) but π − rad(φ) only to ulp(π)/s (2.5e-8 relative at 179.999999°, 2.5 % at 180° − 1e-12°).
// Independent values in long double from the degree difference: the β lower bound is s itself, and
// the change-point design at β = s has a = sin(ψ/2)·sin(s/2)/cos(s/2 + ψ/2) (the crank folds back on
// the coupler: relative error of a = that of s).
TEST(KhareDaveNear180, SupplementFromDegreesKeepsFullRelativePrecision) {
  using loom::motion::CrankRotation;
  using loom::motion::khare_dave_beta_bounds;
  using loom::motion::khare_dave_crank_rocker;
  const long double pi_l = 3.141592653589793238462643383279502884L;
  const double psi_deg = 45.0;
  for (const double phi_deg : {179.999999, 180.0 - 1e-12, 179.9}) {
    const long double s = (180.0L - static_cast<long double>(phi_deg)) * pi_l / 180.0L;
    const long double half_psi = static_cast<long double>(psi_deg) * pi_l / 360.0L;
    const CrankRotation phi = CrankRotation::degrees(phi_deg);
    const auto bounds = khare_dave_beta_bounds(loom::motion::rad(psi_deg), phi);
    EXPECT_NEAR(bounds.lower_rad, static_cast<double>(s), 4e-16 * static_cast<double>(s)) << phi_deg;
    const CrankRockerDesign d = khare_dave_crank_rocker(loom::motion::rad(psi_deg), phi, bounds.lower_rad);
    const long double a = std::sin(half_psi) * std::sin(s / 2.0L) / std::cos(s / 2.0L + half_psi);
    EXPECT_NEAR(d.crank, static_cast<double>(a), 1e-14 * static_cast<double>(a)) << phi_deg;
    EXPECT_TRUE(d.flags & kDesignChangePoint);
  }
  // The radian entry point keeps its documented precision: π − φ_rad (worse than the degree path).
  const double phi_rad = loom::motion::rad(179.999999);
  const auto coarse = khare_dave_beta_bounds(loom::motion::rad(psi_deg), phi_rad);
  const double s = static_cast<double>((180.0L - static_cast<long double>(179.999999)) * pi_l / 180.0L);
  EXPECT_NEAR(coarse.lower_rad, s, 1e-7 * s);
}
