// The profile set as the loop sees it: default tables within their bound against the exact linkage,
// carriage-step peaks that agree with finite differences of the cam played in time, the helix pick
// held under the carrier's limit, and the beater through the crank law by the chain rule.
#include "loom/motion/profile_set.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

using namespace loom::motion;

namespace {

ProfileSpec elliptic_spec(double e = 0.2) {
  ProfileSpec s;
  s.crank_law.kind = CrankLawKind::kElliptic;
  s.crank_law.ellipse_e = e;
  return s;
}

// Peaks of the carriage played in time at cruise: x(t) = cam(crank(ω t)), by central differences.
CarriagePeaks peaks_by_differences(const ProfileSet& p) {
  const double omega = p.spec().crank.velocity, dt = 2e-5;
  const auto x = [&](double t) {
    const double master = 2 * kTwoPi + omega * t;  // mid-sweep, at cruise
    return p.cam().at(master + p.crank_law().exact(master).offset).position;
  };
  CarriagePeaks k;
  for (double t = 0; t < kTwoPi / omega; t += dt / 3) {
    const double xm2 = x(t - 2 * dt), xm = x(t - dt), x0 = x(t), xp = x(t + dt), xp2 = x(t + 2 * dt);
    k.speed_m_s = std::max(k.speed_m_s, std::abs(xp - xm) / (2 * dt));
    k.accel_m_s2 = std::max(k.accel_m_s2, std::abs(xp - 2 * x0 + xm) / (dt * dt));
    k.jerk_m_s3 = std::max(k.jerk_m_s3, std::abs(xp2 - 2 * xp + 2 * xm - xm2) / (2 * dt * dt * dt));
  }
  return k;
}

std::string build_error(const ProfileSpec& s) {
  try {
    ProfileSet p(s);
  } catch (const MotionError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ProfileSet, DefaultTablesMeetTheirBoundAgainstTheExactLinkage) {
  for (const ProfileSpec& spec : {ProfileSpec{}, elliptic_spec()}) {
    const ProfileSet p(spec);
    EXPECT_EQ(p.rocker().size(), spec.table_size);
    EXPECT_EQ(p.crank_law().table().size(), spec.table_size);
    EXPECT_LE(p.rocker_table_error(), 1e-7);
    double worst = 0, worst_master = 0;
    for (int j = 0; j < 20000; ++j) {
      const Phase m{0, 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(j + 1)};
      worst = std::max(worst, std::abs(p.rocker().at(m).value - p.beatup().at(m.frac_rad()).rocker_angle));
      // The beater through the crank law, against the exact linkage at the exact crank phase.
      const double crank = m.frac_rad() + p.crank_law().exact(m.frac_rad()).offset;
      worst_master =
          std::max(worst_master, std::abs(p.rocker_at(m).value - p.beatup().at(crank).rocker_angle));
    }
    EXPECT_LT(worst, 1e-7);
    EXPECT_LT(worst_master, 1e-7);
  }
}

TEST(ProfileSet, RockerAtMasterChainsThroughTheCrankLaw) {
  const ProfileSet p(elliptic_spec(0.3));
  const double h = 1e-5;
  for (int i = 0; i < 90; ++i) {
    const double m = kTwoPi * (i + 0.5) / 90.0;
    const PhaseSample s = p.rocker_at(Phase::from_rad(m));
    const double a = p.rocker_at(Phase::from_rad(m - h)).value, b = p.rocker_at(Phase::from_rad(m + h)).value;
    EXPECT_NEAR(s.d1, (b - a) / (2 * h), 1e-5) << m;
    EXPECT_NEAR(s.d2, (b - 2 * s.value + a) / (h * h), 2e-2) << m;
  }
}

TEST(ProfileSet, CarriagePeaksAgreeWithTheCamPlayedInTime) {
  for (const ProfileSpec& spec : {ProfileSpec{}, elliptic_spec(0.2), elliptic_spec(0.4)}) {
    const ProfileSet p(spec);
    const CarriagePeaks fd = peaks_by_differences(p), k = p.carriage_peaks();
    EXPECT_NEAR(k.speed_m_s, fd.speed_m_s, 1e-4 * fd.speed_m_s);
    EXPECT_NEAR(k.accel_m_s2, fd.accel_m_s2, 1e-3 * fd.accel_m_s2);
    EXPECT_NEAR(k.jerk_m_s3, fd.jerk_m_s3, 1e-2 * fd.jerk_m_s3);
    EXPECT_LE(k.speed_m_s, spec.carriage_max_speed_m_s);
    EXPECT_LE(k.accel_m_s2, spec.carriage_max_accel_m_s2);
    EXPECT_LE(k.jerk_m_s3, spec.carriage_max_jerk_m_s3);
  }
}

TEST(ProfileSet, HelixPickStaysUnderTheCarrierLimit) {
  ProfileSpec s;
  s.carrier_force_n = 5.0;  // weak carrier: 12.5 m/s^2 on a 0.4 kg shuttle
  const ProfileSet p(s);
  const double limit_rad_s2 = 5.0 / 0.4 * kTwoPi / s.helix_lead_m;
  EXPECT_NEAR(p.helix_accel_limit(), limit_rad_s2, 1e-9);
  double peak = 0;
  for (double t = 0; t <= p.pick().duration(); t += 1e-4)
    peak = std::max(peak, std::abs(p.pick().at(t).acceleration));
  EXPECT_LE(peak, limit_rad_s2 * (1 + 1e-12));
  EXPECT_GT(peak, 0.99 * limit_rad_s2);  // the limit binds
  EXPECT_NEAR(p.pick().at(p.pick().duration()).position, kTwoPi * s.width_m / s.helix_lead_m, 1e-12);
  // The default carrier (50 m/s^2) is above the drive's 3000 rad/s^2 (47.7 m/s^2): the drive binds.
  EXPECT_NEAR(ProfileSet(ProfileSpec{}).helix_accel_limit(), 3000.0, 1e-12);
}

TEST(ProfileSet, ShedWindowsAreValidatedWithTheSet) {
  ProfileSpec s;
  s.shed.timeout_s = 0.2;  // shorter than the stroke
  EXPECT_NE(build_error(s).find("shedding.timeout_s = 0.2"), std::string::npos);
}
