// Planar geometry shared by every linkage solver in motion/ (four-bar, needle six-bar, batten drive,
// Khare–Dave synthesis): the four-bar loop closed as a two-circle intersection on a named side, its
// crank-rocker test and dead centres, the range of cos over an arc, and Kahan's triangle angle.
// One implementation, so the branch conventions and rounding guards cannot drift apart. Internal.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::motion::detail {

struct CircleIntersection {
  Eigen::Vector2d point;  // on the chosen side; the tangent point when `clamped`
  double margin;          // signed distance from tangency (length): min(r0 + r1 − d, d − |r0 − r1|);
                          // < 0 by how much the circles miss each other
  bool clamped;           // the height rounded (or fell) to zero or below: a tangent (toggle) pose
};

// RT-safe. The point at distance r0 from c0 and r1 from c1 (|c1 - c0| = d), on the left (left = true)
// or right of the directed line c0 -> c1, from the two Heron factors inner = d² - (r0 - r1)² and
// outer = (r0 + r1)² - d², which a caller that knows where d comes from can compute without
// cancellation (the four-bar does, so a change-point linkage keeps full accuracy beside its flat
// pose). The height sqrt(inner·outer)/(2d) keeps its accuracy for needle-like triangles where acos of
// a law-of-cosines cosine loses half the digits; a product at or below zero is clamped to the tangent
// point and reported, never a NaN.
inline CircleIntersection circle_intersection(const Eigen::Vector2d& c0, double r0, const Eigen::Vector2d& c1,
                                              double r1, bool left, double inner, double outer) {
  const Eigen::Vector2d dv = c1 - c0;
  const double d = dv.norm();
  if (!(d > 0.0)) {  // concentric: no direction to measure from
    return {c0 + Eigen::Vector2d(r0, 0.0), -std::abs(r0 - r1), true};
  }
  const double margin = std::min(outer / (r0 + r1 + d), inner / (d + std::abs(r0 - r1)));
  const bool clamped = !(inner > 0.0) || !(outer > 0.0);
  const double h = clamped ? 0.0 : std::sqrt(inner * outer) / (2.0 * d);
  const double a = (d * d + r0 * r0 - r1 * r1) / (2.0 * d);
  const Eigen::Vector2d ex = dv / d;
  const Eigen::Vector2d ey(-ex.y(), ex.x());
  return {c0 + a * ex + (left ? h : -h) * ey, margin, clamped};
}

// RT-safe. As above with the Heron factors formed from d itself, as products of sums and
// differences (accurate away from tangency).
inline CircleIntersection circle_intersection(const Eigen::Vector2d& c0, double r0, const Eigen::Vector2d& c1,
                                              double r1, bool left) {
  const double d = (c1 - c0).norm();
  const double dr = std::abs(r0 - r1);
  return circle_intersection(c0, r0, c1, r1, left, (d - dr) * (d + dr), (r0 + r1 - d) * (r0 + r1 + d));
}

// RT-safe. As circle_intersection, for a mechanism already validated to assemble (a tangency that
// rounds a hair below zero gives the tangent point).
inline Eigen::Vector2d circle_intersection_valid(const Eigen::Vector2d& c0, double r0,
                                                 const Eigen::Vector2d& c1, double r1, bool left) {
  return circle_intersection(c0, r0, c1, r1, left).point;
}

// ---- the four-bar loop --------------------------------------------------------------------------
// Every linkage here contains a four-bar: crank pivot P (crank r1), rocker pivot Q (rocker r3),
// coupler r2 from the crank pin to the rocker pin. The assembly branch is named once, as the side of
// the rocker pin relative to the directed line Q -> crank pin.

// RT-safe. The rocker pin for crank pin `crank_pin` (see above for the side convention).
inline CircleIntersection rocker_pin(const Eigen::Vector2d& rocker_pivot, double rocker,
                                     const Eigen::Vector2d& crank_pin, double coupler, bool left) {
  return circle_intersection(rocker_pivot, rocker, crank_pin, coupler, left);
}

// RT-safe. The same for a four-bar in its standard frame (crank pivot at the origin, rocker pivot at
// (ground, 0), crank angle θ2), with the diagonal's Heron factors written as
//   f² − (b − c)² = (|d − a| − |b − c|)(|d − a| + |b − c|) + 4ad·sin²(θ2/2)
//   (b + c)² − f² = (b + c − d − a)(b + c + d + a) + 4ad·cos²(θ2/2)
// so that no cancellation happens near the flat poses θ2 = 0, π of a change-point linkage.
inline CircleIntersection rocker_pin_standard(double ground, double crank, double coupler, double rocker,
                                              double theta2, bool left) {
  const double s = std::sin(0.5 * theta2), c = std::cos(0.5 * theta2);
  const double da = std::abs(ground - crank), bc = std::abs(coupler - rocker);
  const double four_ad = 4.0 * ground * crank;
  const double inner = (da - bc) * (da + bc) + four_ad * s * s;
  const double outer =
      (coupler + rocker - ground - crank) * (coupler + rocker + ground + crank) + four_ad * c * c;
  const Eigen::Vector2d pin(crank * std::cos(theta2), crank * std::sin(theta2));
  return circle_intersection(Eigen::Vector2d(ground, 0.0), rocker, pin, coupler, left, inner, outer);
}

// How a four-bar's input link turns: fully (strict crank-rocker or drag link), only up to a
// change point where the links fold flat, or not at all (blocked).
enum class CrankTurn { kFull, kChangePoint, kBlocked };

// RT-safe. Whether the crank r1 can turn fully about P with ground g = |PQ|: the diagonal |crank pin
// - Q| sweeps [|g - r1|, g + r1] and must stay strictly inside (|r2 - r3|, r2 + r3). Equality within
// 1e-12 of the largest link is the change point.
inline CrankTurn crank_turn(double ground, double crank, double coupler, double rocker) {
  const double big = std::max({ground, crank, coupler, rocker});
  const double tol = 1e-12 * big;
  const double short_margin = std::abs(ground - crank) - std::abs(coupler - rocker);
  const double long_margin = (coupler + rocker) - (ground + crank);
  if (short_margin < -tol || long_margin < -tol) return CrankTurn::kBlocked;
  if (short_margin <= tol || long_margin <= tol) return CrankTurn::kChangePoint;
  return CrankTurn::kFull;
}

struct DeadCentrePins {
  Eigen::Vector2d extended;  // rocker pin with crank and coupler stretched in line (|P B| = r2 + r1)
  Eigen::Vector2d folded;    // ... folded over each other (|P B| = r2 - r1)
};

// RT-safe. Rocker pin at the two dead centres of a crank-rocker (r1 < r2), on branch `left`. There
// the crank pin lies on the line P-B on the same side of B as P, so the side of B relative to
// Q -> crank pin equals its side relative to Q -> P: each pin is one circle intersection.
inline DeadCentrePins dead_centre_pins(const Eigen::Vector2d& crank_pivot,
                                       const Eigen::Vector2d& rocker_pivot, double crank, double coupler,
                                       double rocker, bool left) {
  return {circle_intersection_valid(rocker_pivot, rocker, crank_pivot, coupler + crank, left),
          circle_intersection_valid(rocker_pivot, rocker, crank_pivot, coupler - crank, left)};
}

// ---- angles ---------------------------------------------------------------------------------------

struct CosRange {
  double min;
  double max;
};

// RT-safe. Smallest and largest cos θ for θ in [lo, hi] (hi >= lo, hi - lo < 2π): the endpoints, plus
// ±1 wherever a multiple of π lies inside the arc.
inline CosRange cos_range(double lo, double hi) {
  CosRange r{std::min(std::cos(lo), std::cos(hi)), std::max(std::cos(lo), std::cos(hi))};
  const double first_even = std::ceil(lo / kTwoPi) * kTwoPi;               // cos = +1
  const double first_odd = std::ceil((lo - kPi) / kTwoPi) * kTwoPi + kPi;  // cos = -1
  if (first_even <= hi) r.max = 1.0;
  if (first_odd <= hi) r.min = -1.0;
  return r;
}

// RT-safe. Angle opposite side r in the triangle with sides (p, q, r), by Kahan's formula: accurate
// for needle-like triangles (a linkage near its change point or toggle), where acos of the
// law-of-cosines cosine is not. Sides that cannot close clamp to 0 or π.
inline double triangle_angle(double r, double p, double q) {
  if (p < q) std::swap(p, q);
  const double mu = (q >= r) ? r - (p - q) : q - (p - r);
  const double num = ((p - q) + r) * mu;
  const double den = (p + (q + r)) * ((p - r) + q);
  if (!(num > 0.0)) return 0.0;
  if (!(den > 0.0)) return kPi;
  return 2.0 * std::atan(std::sqrt(num / den));
}

}  // namespace loom::motion::detail
