// Link mass properties: the plate formula against an independent numerical integration, the
// parallel-axis combination, and what thesis Table 5.1 actually computed.
#include "loom/motion/mass_properties.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/errors.hpp"

using namespace loom::motion;

namespace {

// Central inertia of a uniform w × L plate by midpoint-rule integration of ρt(x² + y²) dA.
double plate_inertia_numeric(double length, double width, double areal_density) {
  const int nx = 2000, ny = 400;
  double sum = 0.0;
  for (int i = 0; i < nx; ++i) {
    const double x = -0.5 * length + (i + 0.5) * length / nx;
    for (int j = 0; j < ny; ++j) {
      const double y = -0.5 * width + (j + 0.5) * width / ny;
      sum += x * x + y * y;
    }
  }
  return sum * areal_density * (length / nx) * (width / ny);
}

}  // namespace

TEST(MassProperties, BarMatchesNumericalIntegration) {
  const BarSection s{0.03, 0.01};
  const PlanarInertia b = bar_link(0.189, s, kCastIronDensity_kg_m3);
  EXPECT_NEAR(b.mass_kg, kCastIronDensity_kg_m3 * 0.189 * 0.03 * 0.01, 1e-15);
  EXPECT_DOUBLE_EQ(b.centre_m.x(), 0.0945);
  const double numeric = plate_inertia_numeric(0.189, 0.03, kCastIronDensity_kg_m3 * 0.01);
  EXPECT_NEAR(b.inertia_kg_m2, numeric, 1e-6 * numeric);  // midpoint rule error ~ h²
}

TEST(MassProperties, CombineIsTheParallelAxisTheorem) {
  const PlanarInertia a{2.0, {0.1, 0.0}, 0.003};
  const PlanarInertia b{0.5, {-0.2, 0.05}, 0.001};
  const PlanarInertia c = combine(a, b);
  EXPECT_DOUBLE_EQ(c.mass_kg, 2.5);
  EXPECT_NEAR(c.centre_m.x(), (2.0 * 0.1 - 0.5 * 0.2) / 2.5, 1e-15);
  EXPECT_NEAR(c.centre_m.y(), 0.5 * 0.05 / 2.5, 1e-15);
  // Inertia about any point is additive.
  const Eigen::Vector2d p(0.3, -0.7);
  EXPECT_NEAR(c.inertia_about(p), a.inertia_about(p) + b.inertia_about(p), 1e-15);
}

TEST(MassProperties, ThesisTable51MassesAreRhoLwtButInertiasUseHalfTheWidth) {
  const ThesisTable51 t;
  const BarSection s;
  const double rho = kCastIronDensity_kg_m3;
  // a2 is printed 0.58 m; only 0.058 m reproduces m2 (and 0.301 m, the beater arm, reproduces m4).
  EXPECT_NEAR(rho * 0.058 * s.width_m * s.thickness_m, t.m2_kg, 5e-7);
  EXPECT_GT(std::abs(rho * t.a2_printed_m * s.width_m * s.thickness_m - t.m2_kg), 1.0);
  EXPECT_NEAR(rho * t.a3_m * s.width_m * s.thickness_m, t.m3_kg, 5e-7);
  EXPECT_NEAR(rho * 0.301 * s.width_m * s.thickness_m, t.m4_kg, 5e-7);
  const BeatUpMasses m = beatup_masses(default_beatup_geometry());
  const double lens[3] = {0.058, 0.189, 0.301};
  const double printed[3] = {t.j2_kg_m2, t.j3_kg_m2, t.j4_kg_m2};
  const PlanarInertia* ours[3] = {&m.crank, &m.coupler, &m.rocker};
  for (int i = 0; i < 3; ++i) {
    const double half_width = ours[i]->mass_kg * (lens[i] * lens[i] + 0.25 * s.width_m * s.width_m) / 12.0;
    EXPECT_NEAR(half_width, printed[i], 1e-6 * printed[i]) << i;  // printed to 6-7 digits
    EXPECT_GT(ours[i]->inertia_kg_m2, printed[i] * 1.005) << i;   // ours uses the full width
  }
  EXPECT_NEAR(1.0 - t.j2_kg_m2 / m.crank.inertia_kg_m2, 0.158, 0.001);
}

TEST(MassProperties, BadInputsAreNamed) {
  try {
    (void)bar_link(-0.1);
    FAIL();
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("bar length"), std::string::npos);
  }
  EXPECT_THROW((void)point_mass(std::nan(""), {0, 0}), MotionError);
  EXPECT_THROW((void)beatup_masses(default_beatup_geometry(), -2.5), MotionError);
}
