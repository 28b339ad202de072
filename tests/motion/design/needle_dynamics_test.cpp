// Needle six-bar (002) inverse dynamics against independent truths: the power balance (balancing
// torque × ω = rate of kinetic + potential energy + power lost to the backing), the momentum balance
// of the whole mechanism, and virtual work with the friction alone.
#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/design/dynamics_needle.hpp"

using namespace loom::motion;

namespace {

constexpr double kOmega = 160.0 * 2.0 * 3.141592653589793 / 60.0;  // 002's 160 r/min

}  // namespace

TEST(NeedleDynamics, BalancingTorquePowerEqualsEnergyRatePlusFrictionLoss) {
  const NeedleLinkage nl(needle_table1());
  const NeedleMasses m = needle_table1_masses();
  const NeedleLoads loads;
  const std::array<PlanarInertia, 6> bodies = needle_bodies(nl, m);
  for (const NeedleForces& f : needle_dynamics_sweep(nl, m, 180, kOmega, loads)) {
    const std::array<BodyMotion, 6> mo = needle_motion(nl, f.state);
    double de = 0.0;
    for (std::size_t i = 0; i < 6; ++i) {
      const Eigen::Vector2d v = mo[i].velocity(bodies[i].centre_m),
                            a = mo[i].acceleration(bodies[i].centre_m);
      de += bodies[i].mass_kg * (v.dot(a) - loads.gravity_m_s2.dot(v)) +
            bodies[i].inertia_kg_m2 * mo[i].omega_rad_s * mo[i].alpha_rad_s2;
    }
    const double loss = std::abs(f.friction_n * f.state.needle_v_m_s);
    const double input = f.balancing_torque_nm * kOmega;
    EXPECT_NEAR(input, de + loss, 1e-9 * (std::abs(de) + loss + 1.0)) << f.state.theta1_rad;
  }
}

TEST(NeedleDynamics, FrameReactionsBalanceTheMomentum) {
  // Σ m a = frame forces at O and C + guide + backing friction + weight.
  const NeedleLinkage nl(needle_table1());
  const NeedleMasses m = needle_table1_masses();
  const NeedleLoads loads;
  const std::array<PlanarInertia, 6> bodies = needle_bodies(nl, m);
  double total = 0.0;
  for (const double mi : m.mass_kg) total += mi;
  for (const NeedleForces& f : needle_dynamics_sweep(nl, m, 72, kOmega, loads)) {
    const std::array<BodyMotion, 6> mo = needle_motion(nl, f.state);
    Eigen::Vector2d ma = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < 6; ++i) ma += bodies[i].mass_kg * mo[i].acceleration(bodies[i].centre_m);
    const Eigen::Vector2d ext =
        f.pin_o_n + f.pin_c_n() + Eigen::Vector2d(f.guide_n, f.friction_n) + total * loads.gravity_m_s2;
    EXPECT_NEAR((ma - ext).norm(), 0.0, 1e-9 * (1.0 + ext.norm()));
    // The needle bar really slides vertically: E has no horizontal velocity.
    EXPECT_NEAR(mo[5].origin_vel_m_s.x(), 0.0, 1e-12);
  }
}

TEST(NeedleDynamics, FrictionAloneGivesVirtualWorkTorque) {
  // Massless linkage: M_b = F_r·|d(needle)/dθ1|, and the friction reverses with the needle.
  const NeedleLinkage nl(needle_table1());
  NeedleMasses zero;
  NeedleLoads loads;
  loads.gravity_m_s2 = Eigen::Vector2d::Zero();
  int down = 0, up = 0;
  for (const NeedleForces& f : needle_dynamics_sweep(nl, zero, 90, 1.0, loads)) {
    const double dneedle = f.state.needle_v_m_s;  // per rad at ω1 = 1
    EXPECT_NEAR(f.balancing_torque_nm, loads.friction_n * std::abs(dneedle), 1e-9 * loads.friction_n);
    EXPECT_EQ(f.friction_n > 0.0, dneedle > 0.0);
    (dneedle > 0.0 ? down : up) += 1;
  }
  EXPECT_GT(down, 10);
  EXPECT_GT(up, 10);
}
