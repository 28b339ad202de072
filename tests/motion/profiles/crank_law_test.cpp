// The crank speed law: the elliptic law is exactly the constant law at e = 0 (bit for bit, table and
// closed form), approaches it continuously as e → 0, keeps park at park, puts the gear's fastest
// point at the fell for φ02 = π/k, and its derivatives agree with finite differences.
#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/angles.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/profile_crank.hpp"

using namespace loom::motion;

namespace {

const double kFell = BeatUp(default_beatup_geometry()).warp().fell;
const TableSpec kTable{.size = 256, .interp = Interp::kCubic, .precision = Precision::kDouble};

CrankLaw elliptic(double e, int lobes = 1, double phi02 = kPi, const TableSpec& t = kTable) {
  return CrankLaw(
      {.kind = CrankLawKind::kElliptic, .ellipse_e = e, .ellipse_lobes = lobes, .ellipse_phi02_rad = phi02},
      kFell, t);
}

Phase weyl(int j) {
  return Phase{j % 7 - 3, 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(j + 1)};
}

// Master phase at which the crank reaches `crank` (the law is increasing).
double master_at(const CrankLaw& law, double crank) {
  double lo = crank - kTwoPi, hi = crank + kTwoPi;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (mid + law.exact(mid).offset < crank ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

TEST(CrankLaw, ParkIsParkAndTheCrankTurnsOncePerMasterTurn) {
  for (double e : {0.1, 0.3, 0.6}) {
    for (int lobes : {1, 2}) {
      const CrankLaw law = elliptic(e, lobes, 1.0);
      EXPECT_EQ(law.exact(0.0).offset, 0.0) << e << " " << lobes;
      EXPECT_NEAR(law.exact(kTwoPi).offset, 0.0, 1e-12) << e << " " << lobes;
      EXPECT_NEAR(law.exact(-3 * kTwoPi + 1.0).offset, law.exact(1.0).offset, 1e-12);
      // Strictly increasing: the speed ratio stays within [(1-e)/(1+e), (1+e)/(1-e)].
      for (int i = 0; i < 720; ++i) {
        const double r = law.exact(kTwoPi * i / 720.0).d1;
        EXPECT_GE(r, law.min_ratio() * (1 - 1e-12));
        EXPECT_LE(r, law.max_ratio() * (1 + 1e-12));
      }
    }
  }
}

// The crank passes the fell where the driven pinion stands at φ02; φ02 = π/k is the pair's fastest
// point, (1+e)/(1-e), and φ02 = 0 its slowest, (1-e)/(1+e).
TEST(CrankLaw, Phi02PlacesTheFastestPointAtTheFell) {
  for (int lobes : {1, 2}) {
    const double e = 0.25;
    const CrankLaw fast = elliptic(e, lobes, kPi / lobes), slow = elliptic(e, lobes, 0.0);
    EXPECT_NEAR(fast.exact(master_at(fast, kFell)).d1, (1 + e) / (1 - e), 1e-9) << lobes;
    EXPECT_NEAR(slow.exact(master_at(slow, kFell)).d1, (1 - e) / (1 + e), 1e-9) << lobes;
  }
}

TEST(CrankLaw, DerivativesMatchFiniteDifferences) {
  const CrankLaw law = elliptic(0.4, 1, 2.0);
  const double h = 1e-4;
  for (int i = 0; i < 97; ++i) {
    const double m = kTwoPi * (i + 0.3) / 97.0;
    const CrankLawExact x = law.exact(m);
    const CrankLawExact a = law.exact(m - h), b = law.exact(m + h);
    EXPECT_NEAR(x.d1, 1.0 + (b.offset - a.offset) / (2 * h), 1e-7) << m;
    EXPECT_NEAR(x.d2, (b.d1 - a.d1) / (2 * h), 1e-6) << m;
    EXPECT_NEAR(x.d3, (b.d2 - a.d2) / (2 * h), 1e-5 * std::max(1.0, std::abs(x.d3))) << m;
  }
}

TEST(CrankLaw, TableFollowsTheClosedForm) {
  const CrankLaw law = elliptic(0.2);
  for (int j = 0; j < 5000; ++j) {
    const Phase m = weyl(j);
    const CrankLawExact x = law.exact(m.to_rad());
    const CrankSample s = law.at(m);
    EXPECT_NEAR(s.phase, m.to_rad() + x.offset, 2e-9);
    EXPECT_NEAR(s.d1, x.d1, 1e-5);
    EXPECT_NEAR(law.crank_phase(m).to_rad(), s.phase, 1e-12);
  }
}

TEST(CrankLaw, RejectsBadParametersNamingThem) {
  const auto message = [](double e, int lobes, double phi02) -> std::string {
    try {
      elliptic(e, lobes, phi02);
    } catch (const MotionError& x) {
      return x.what();
    }
    return "";
  };
  EXPECT_NE(message(1.0, 1, 0).find("ellipse_e = 1"), std::string::npos);
  EXPECT_NE(message(-0.1, 1, 0).find("ellipse_e"), std::string::npos);
  EXPECT_NE(message(NAN, 1, 0).find("ellipse_e"), std::string::npos);
  EXPECT_NE(message(0.2, 0, 0).find("ellipse_lobes"), std::string::npos);
  EXPECT_NE(message(0.2, 1, INFINITY).find("ellipse_phi02"), std::string::npos);
  CrankLawKind k{};
  EXPECT_TRUE(parse_crank_law("elliptic", k));
  EXPECT_EQ(k, CrankLawKind::kElliptic);
  EXPECT_FALSE(parse_crank_law("ellipse", k));
}
