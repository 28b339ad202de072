// Equimomental (dynamically equivalent) point-mass systems of a planar link, seed 003 eqns 1–4: three
// point masses fixed in the link frame with the link's mass, centre of mass and moment of inertia, so
// that shaking force and moment can be written — and optimised — in terms of point-mass parameters.
// 003's choice (eqns 18a–b): angles 0, 2π/3, 4π/3 and one common distance l from the link origin.
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>

#include "loom/motion/mass_properties.hpp"

namespace loom::motion {

struct PointMass {
  double mass_kg = 0.0;
  Eigen::Vector2d at_m = Eigen::Vector2d::Zero();  // in the link frame
};

struct EquimomentalSystem {
  std::array<PointMass, 3> points;
  double radius_m = 0.0;  // l = sqrt(I_O / m): the common distance from the link origin
  // Every point mass >= 0. Always so when the offset points at the centre of mass (d <= l holds for
  // any body); for other offsets guaranteed only when d <= l/2.
  bool all_positive = false;
};

// Configure-time only. The three-point system of `body` with masses at angles offset + 0, 2π/3, 4π/3
// and distance l = sqrt(I_O/m) (I_O about the link origin, eqn 4 with equal l). The masses follow in
// closed form, m_j = (m/3)(1 + 2(d/l)cos(θ_j − θ_d)), which satisfies eqns 1–3. Throws
// MotionError(kInvalidInput) for a non-positive or non-finite mass, or a non-finite centre/inertia.
EquimomentalSystem equimomental_three(const PlanarInertia& body, double offset_rad = 0.0);

// Configure-time only. The same system from 003's own data: mass, centre in the link frame and the
// inertia about the link origin I_O (eqn 4's right-hand side). I_O below m·|c|² belongs to no rigid body
// (a rounded table at constraint 20e's bound): the masses still satisfy eqns 1–4, one of them negative
// (all_positive false). Throws kInvalidInput for a non-positive mass, negative I_O or non-finite input.
EquimomentalSystem equimomental_three_origin(double mass_kg, const Eigen::Vector2d& centre_m,
                                             double inertia_origin_kg_m2, double offset_rad = 0.0);

// RT-safe. 003's design-variable form (eqn 16 with eqns 18a–b): masses m1, m2, m3 at distance l and
// angles offset + 0, 2π/3, 4π/3 in the link frame.
std::array<PointMass, 3> equimomental_points(double m1_kg, double m2_kg, double m3_kg, double l_m,
                                             double offset_rad = 0.0);

// RT-safe. Eqns 1–4 read the other way: total mass, centre of mass and central moment of inertia of
// point masses fixed in one link frame. A massless set gives a zero body at the origin.
PlanarInertia from_point_masses(std::span<const PointMass> points);

}  // namespace loom::motion
