// Shaking balance: the linear shaking model against the direct rigid-body sum, its analytic gradient
// against finite differences, force-only balancing against the Berkof–Lowen closed form (a four-bar
// is fully force-balanced by two counterweights whose first moments are known), and the reductions
// on the default beat-up with converged SLSQP runs that respect their bounds.
#include "loom/motion/design/balancing.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "loom/motion/errors.hpp"

using namespace loom::motion;

namespace {

BeatUpDynamics thesis_beatup() {
  const BeatUpGeometry g = default_beatup_geometry();
  return BeatUpDynamics(g, beatup_masses(g));
}

std::vector<double> parameters(const LinkageMotionSamples& s) {
  std::vector<double> q;
  for (const BalancingLink& l : s.links) {
    const MassParameters p = mass_parameters(l.body) + mass_parameters(l.payload);
    q.insert(q.end(), p.data(), p.data() + 4);
  }
  return q;
}

}  // namespace

TEST(Balancing, LinearShakingModelEqualsRigidBodySum) {
  const BeatUpDynamics d = thesis_beatup();
  LinkageMotionSamples s = beatup_balancing_samples(d, 15.5, 90);
  s.moment_about_m = {0.05, -0.02};  // any reference point
  const ShakingModel model(s);
  const std::vector<double> q = parameters(s);
  for (std::size_t k = 0; k < s.samples; ++k) {
    std::vector<PlanarInertia> bodies;
    for (const BalancingLink& l : s.links) bodies.push_back(combine(l.body, l.payload));
    const ShakingLoad direct = shaking_load(
        bodies, std::span(s.motion).subspan(k * s.links.size(), s.links.size()), s.moment_about_m);
    const ShakingLoad linear = model.load(k, q);
    EXPECT_NEAR((direct.force_n - linear.force_n).norm(), 0.0, 1e-12 * (1.0 + direct.force_n.norm()));
    EXPECT_NEAR(direct.moment_nm, linear.moment_nm, 1e-12 * (1.0 + std::abs(direct.moment_nm)));
  }
}

TEST(Balancing, RmsGradientMatchesFiniteDifferences) {
  const BeatUpDynamics d = thesis_beatup();
  const LinkageMotionSamples s = beatup_balancing_samples(d, 15.5, 72);
  const ShakingModel model(s);
  std::vector<double> q = parameters(s);
  std::vector<double> df(q.size()), dn(q.size());
  (void)model.rms(q, df, dn);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::abs(q[i]));
    std::vector<double> qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    const ShakingRms p = model.rms(qp), m = model.rms(qm);
    EXPECT_NEAR(df[i], (p.force_n - m.force_n) / (2 * h), 1e-6 * (1.0 + std::abs(df[i]))) << i;
    EXPECT_NEAR(dn[i], (p.moment_nm - m.moment_nm) / (2 * h), 1e-6 * (1.0 + std::abs(dn[i]))) << i;
  }
}

TEST(Balancing, ForceOnlyBalanceReproducesBerkofLowen) {
  // Total first moment stays constant iff (crank) m2·r2 = −m3·a·(1 − r3/b) and (rocker)
  // m4·r4 = −m3·c·r3/b along each link's axis, r3 the coupler centre's distance from A.
  const BeatUpDynamics d = thesis_beatup();
  const LinkageMotionSamples s = beatup_balancing_samples(d, 15.5, 180);
  BalanceOptions o;
  o.w1 = 1.0;
  o.w2 = 0.0;
  const BalanceResult r = balance_with_counterweights(s, o);
  EXPECT_LT(r.after.force_n, 1e-4 * r.before.force_n);
  const FourBar& bar = d.head().geometry().bar;
  const PlanarInertia& coupler = s.links[1].body;
  const double m3 = coupler.mass_kg, r3 = coupler.centre_m.x();
  const Eigen::Vector2d crank_needed(-m3 * bar.crank * (1.0 - r3 / bar.coupler), 0.0);
  const Eigen::Vector2d rocker_needed(-m3 * bar.rocker * r3 / bar.coupler, 0.0);
  ASSERT_EQ(r.links_after.size(), 3u);
  const PlanarInertia crank = r.links_after[0];
  const PlanarInertia rocker = combine(r.links_after[2], s.links[2].payload);
  EXPECT_NEAR((crank.mass_kg * crank.centre_m - crank_needed).norm(), 0.0, 1e-4 * crank_needed.norm());
  EXPECT_NEAR((rocker.mass_kg * rocker.centre_m - rocker_needed).norm(), 0.0, 1e-4 * rocker_needed.norm());
  for (const Counterweight& c : r.counterweights) {
    EXPECT_LE(c.mass_kg, o.counterweight_max_kg);
    EXPECT_GE(c.radius_m, 0.0);
  }
}

TEST(Balancing, CounterweightsReduceBothOnTheBeatUp) {
  const BeatUpDynamics d = thesis_beatup();
  const LinkageMotionSamples s = beatup_balancing_samples(d, 15.5, 360);
  const BalanceResult r = balance_with_counterweights(s, BalanceOptions{});
  EXPECT_TRUE(r.converged) << r.stop_reason;
  EXPECT_NEAR(r.objective_before, 1.0, 1e-12);
  EXPECT_LT(r.objective_after, r.objective_before);
  EXPECT_GT(r.force_reduction(), 0.05);
  EXPECT_GT(r.moment_reduction(), 0.0);
  // The trace starts at the starting point and the optimiser never reports a better value than the
  // one it returns.
  ASSERT_FALSE(r.trace.empty());
  for (const OptimiserStep& st : r.trace) EXPECT_GE(st.objective, r.objective_after - 1e-3);
  // Recomputing the shaking of the balanced links directly gives the reported RMS.
  std::vector<ShakingLoad> h;
  for (std::size_t k = 0; k < s.samples; ++k) {
    std::vector<PlanarInertia> bodies;
    for (std::size_t i = 0; i < s.links.size(); ++i)
      bodies.push_back(combine(r.links_after[i], s.links[i].payload));
    h.push_back(shaking_load(bodies, std::span(s.motion).subspan(k * 3, 3), s.moment_about_m));
  }
  const ShakingRms direct = shaking_rms(h);
  EXPECT_NEAR(direct.force_n, r.after.force_n, 1e-9 * r.after.force_n);
  EXPECT_NEAR(direct.moment_nm, r.after.moment_nm, 1e-9 * r.after.moment_nm);
}

TEST(Balancing, RedistributionRespectsItsBoundsAndReduces) {
  const BeatUpDynamics d = thesis_beatup();
  const LinkageMotionSamples s = beatup_balancing_samples(d, 15.5, 360);
  const BalanceOptions o;
  const BalanceResult r = balance_by_redistribution(s, o);
  EXPECT_TRUE(r.converged) << r.stop_reason;
  EXPECT_LT(r.objective_after, r.objective_before);
  for (std::size_t i = 0; i < s.links.size(); ++i) {
    const double m0 = s.links[i].body.mass_kg;
    EXPECT_GE(r.links_after[i].mass_kg, m0 * (1.0 - 1e-9));
    EXPECT_LE(r.links_after[i].mass_kg, o.mass_factor_max * m0 * (1.0 + 1e-9));
    EXPECT_LE(r.links_after[i].centre_m.norm(), s.links[i].length_m * (1.0 + 1e-9));
    EXPECT_GE(r.links_after[i].inertia_kg_m2, -1e-12);
  }
}

TEST(Balancing, BadOptionsAreNamed) {
  const BeatUpDynamics d = thesis_beatup();
  const LinkageMotionSamples s = beatup_balancing_samples(d, 15.5, 36);
  BalanceOptions o;
  o.w1 = -1.0;
  try {
    (void)balance_with_counterweights(s, o);
    FAIL();
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("w1"), std::string::npos);
  }
  EXPECT_THROW((void)beatup_balancing_samples(d, -1.0, 36), MotionError);
}
