// Mass properties of planar links from geometry and material: the thesis' cast-iron bars (7210 kg/m³,
// 30 × 10 mm section), point masses such as the 2.5 kg beater, and their combination. Everything the
// dynamics needs (mass, centre, inertia) is computed here rather than copied from Table 5.1, whose
// inertias use half the bar width (see thesis_table_5_1 below). Configure-time helpers, no state.
#pragma once

#include <Eigen/Core>

#include "loom/motion/beatup.hpp"

namespace loom::motion {

// A rigid body's planar mass properties in its own link frame (origin at the link's first joint, x
// along the line to its second joint). inertia_kg_m2 is about the centre of mass, about the plane's
// normal.
struct PlanarInertia {
  double mass_kg = 0.0;
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  double inertia_kg_m2 = 0.0;

  // RT-safe. Inertia about a point of the link frame (parallel-axis theorem).
  double inertia_about(const Eigen::Vector2d& point_m) const {
    return inertia_kg_m2 + mass_kg * (centre_m - point_m).squaredNorm();
  }
};

inline constexpr double kCastIronDensity_kg_m3 = 7210.0;  // thesis §5.2

// Rectangular cross-section of a flat bar link (thesis Figure 5.1: 30 mm wide, 10 mm thick).
struct BarSection {
  double width_m = 0.03;      // in the plane of motion
  double thickness_m = 0.01;  // normal to it
};

// Configure-time only. A uniform flat bar of the given length along +x from the origin: m = ρLwt,
// centre (L/2, 0), I = m(L² + w²)/12 about the centre (a thin rectangular plate about its normal; the
// thickness does not enter). Throws MotionError(kInvalidInput) naming a non-positive/non-finite input.
PlanarInertia bar_link(double length_m, const BarSection& section = {},
                       double density_kg_m3 = kCastIronDensity_kg_m3);

// Configure-time only. A point mass at a place of the link frame. Throws on negative/non-finite mass.
PlanarInertia point_mass(double mass_kg, const Eigen::Vector2d& at_m);

// RT-safe. Two bodies rigidly joined in the same link frame: masses add, centres average by mass,
// inertias move to the common centre by the parallel-axis theorem.
PlanarInertia combine(const PlanarInertia& a, const PlanarInertia& b);

// The moving masses of the beat-up four-bar. Link frames: crank origin A0, x toward A; coupler origin
// A, x toward B; rocker origin B0, x toward B. The beater is a point mass on the rocker frame's x axis
// at the beater arm (the thesis joins it "to the tip of the B0C link with a rigid joint").
struct BeatUpMasses {
  PlanarInertia crank;
  PlanarInertia coupler;
  PlanarInertia rocker;  // the rocker bar alone, without the beater
  double beater_kg = 2.5;
  Eigen::Vector2d beater_at_m{0.301, 0.0};

  // RT-safe. Rocker bar plus beater: the body the rocker's Newton–Euler equations see.
  PlanarInertia rocker_with_beater() const { return combine(rocker, {beater_kg, beater_at_m, 0.0}); }
};

// Configure-time only. The thesis' model of the beat-up: every link a cast-iron bar of `section`; the
// rocker bar runs from B0 through B to the beater at the beater arm (Table 5.1's m4 = ρ·0.301·w·t shows
// the thesis modelled it so), so its length is max(rocker, beater arm). Throws on bad inputs.
BeatUpMasses beatup_masses(const BeatUpGeometry& g, double beater_kg = 2.5, const BarSection& section = {},
                           double density_kg_m3 = kCastIronDensity_kg_m3);

// Thesis Table 5.1 as printed, for comparison (a2 printed as 0.58 m is 0.058 m: its mass m2 =
// ρ·0.058·w·t proves it). Finding: the printed masses are ρLwt exactly, but the printed inertias are
// m(L² + (w/2)²)/12 — the half-width where the plate formula has the full width — so j2, j3, j4 are low
// by 15.8 %, 1.8 % and 0.7 % against m(L² + w²)/12.
struct ThesisTable51 {
  double a1_m = 0.213, a2_printed_m = 0.58, a3_m = 0.189, a4_m = 0.232;
  double m2_kg = 0.125454, m3_kg = 0.408807, m4_kg = 0.651063;
  double j2_kg_m2 = 3.75212e-5, j3_kg_m2 = 1.224581e-3, j4_kg_m2 = 4.927787e-3;
};

}  // namespace loom::motion
