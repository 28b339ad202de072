// Equimomental three-point systems (003 eqns 1–4): they keep the link's mass, centre of mass and
// inertia to 1e-12, their masses are non-negative when the first point faces the centre, and — what
// the equivalence is for — they give the same shaking force and moment as the rigid link in any motion.
#include "loom/motion/design/equimomental.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "loom/motion/angles.hpp"
#include "loom/motion/dynamics_body.hpp"
#include "loom/motion/errors.hpp"

using namespace loom::motion;

namespace {

PlanarInertia random_body(std::mt19937& rng) {
  std::uniform_real_distribution<double> m(0.05, 12.0), c(-0.3, 0.3), k(0.005, 0.2);
  PlanarInertia b;
  b.mass_kg = m(rng);
  b.centre_m = {c(rng), c(rng)};
  const double radius_of_gyration = k(rng);
  b.inertia_kg_m2 = b.mass_kg * radius_of_gyration * radius_of_gyration;
  return b;
}

}  // namespace

TEST(Equimomental, PreservesMassCentreAndInertia) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> off(-kPi, kPi);
  for (int i = 0; i < 500; ++i) {
    const PlanarInertia b = random_body(rng);
    const EquimomentalSystem e = equimomental_three(b, off(rng));
    const PlanarInertia r = from_point_masses(e.points);
    EXPECT_NEAR(r.mass_kg, b.mass_kg, 1e-12 * b.mass_kg);
    EXPECT_NEAR((r.centre_m - b.centre_m).norm(), 0.0, 1e-12 * (b.centre_m.norm() + e.radius_m));
    EXPECT_NEAR(r.inertia_kg_m2, b.inertia_kg_m2, 1e-12 * b.inertia_about(Eigen::Vector2d::Zero()));
    // Eqn 4 directly: Σ m_j l_j² is the inertia about the link origin; all points at distance l.
    double io = 0.0;
    for (const PointMass& p : e.points) {
      EXPECT_NEAR(p.at_m.norm(), e.radius_m, 1e-15);
      io += p.mass_kg * p.at_m.squaredNorm();
    }
    EXPECT_NEAR(io, b.inertia_about(Eigen::Vector2d::Zero()), 1e-12 * io);
  }
}

TEST(Equimomental, MassesAreNonNegativeWhenThePointsFaceTheCentre) {
  std::mt19937 rng(11);
  for (int i = 0; i < 500; ++i) {
    const PlanarInertia b = random_body(rng);
    const double toward = std::atan2(b.centre_m.y(), b.centre_m.x());
    const EquimomentalSystem e = equimomental_three(b, toward);
    EXPECT_TRUE(e.all_positive) << i;
    for (const PointMass& p : e.points) EXPECT_GE(p.mass_kg, -1e-15);
  }
  // A uniform bar about its end (003's links): facing along the bar is non-negative.
  const PlanarInertia bar{1.0, {0.1, 0.0}, 1.0 * 0.2 * 0.2 / 12.0};
  EXPECT_TRUE(equimomental_three(bar, 0.0).all_positive);
  // The same bar with the first point facing away has a negative mass (centre beyond l/2 behind it).
  EXPECT_FALSE(equimomental_three(bar, kPi).all_positive);
}

TEST(Equimomental, SameShakingLoadAsTheRigidLinkInAnyMotion) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int i = 0; i < 200; ++i) {
    const PlanarInertia b = random_body(rng);
    const EquimomentalSystem e = equimomental_three(b, u(rng));
    BodyMotion m;
    m.angle_rad = u(rng);
    m.omega_rad_s = 10 * u(rng);
    m.alpha_rad_s2 = 100 * u(rng);
    m.origin_m = {u(rng), u(rng)};
    m.origin_vel_m_s = {u(rng), u(rng)};
    m.origin_acc_m_s2 = {50 * u(rng), 50 * u(rng)};
    const Eigen::Vector2d about(u(rng), u(rng));
    const ShakingLoad body = shaking_load(std::array{b}, std::array{m}, about);
    std::array<PlanarInertia, 3> pts;
    for (int j = 0; j < 3; ++j) pts[j] = {e.points[j].mass_kg, e.points[j].at_m, 0.0};
    const ShakingLoad three = shaking_load(pts, std::array{m, m, m}, about);
    EXPECT_NEAR((body.force_n - three.force_n).norm(), 0.0, 1e-12 * (1.0 + body.force_n.norm()));
    EXPECT_NEAR(body.moment_nm, three.moment_nm, 1e-11 * (1.0 + std::abs(body.moment_nm)));
    // Kinetic energy too.
    double ke = 0.0;
    for (int j = 0; j < 3; ++j) ke += kinetic_energy(pts[j], m);
    EXPECT_NEAR(ke, kinetic_energy(b, m), 1e-12 * (1.0 + ke));
  }
}

TEST(Equimomental, RejectsAMasslessLink) {
  EXPECT_THROW((void)equimomental_three(PlanarInertia{0.0, {0.1, 0.0}, 0.0}), MotionError);
  EXPECT_THROW((void)equimomental_three(PlanarInertia{1.0, {std::nan(""), 0.0}, 0.0}), MotionError);
}
