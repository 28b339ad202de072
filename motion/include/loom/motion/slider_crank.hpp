// Offset slider-crank analysis: slider position, velocity and acceleration over the crank angle, the
// dead centres, stroke, crank rotations between them, and the transmission angle. The thesis' first
// beat-up model (000 §4.5.1) is a slider-crank, and every Söylemez synthesis is checked against it.
#pragma once

#include <Eigen/Core>

#include "loom/motion/link_point.hpp"

namespace loom::motion {

// Geometry: crank pivot A0 at the origin, crank angle θ measured counter-clockwise from +x; the
// slider's line is y = offset and the slider stays on the +x side of the pivot (the one assembly
// used by the loom). Lengths in any one unit (m in the firmware, stroke = 1 in the synthesis tables).
struct SliderCrank {
  double crank = 0.0;    // a: A0 → crank pin A
  double coupler = 0.0;  // b: A → slider pin B
  double offset = 0.0;   // e: signed distance of the slider line from A0 (the thesis' eccentricity c)
};

// configure-time only. Throws MotionError kInvalidInput for a non-finite or non-positive length,
// kNotCrank when b ≤ a + |e| + 1e-12·b (the crank cannot turn a full revolution without toggling,
// or the linkage is a change point within rounding, where the rates are unbounded).
void validate_slider_crank(const SliderCrank& m);

struct SliderState {
  double x = 0.0;                     // slider pin position along +x
  double x_dot = 0.0;                 // d x / dt
  double x_ddot = 0.0;                // d² x / dt²
  double coupler_angle_rad = 0.0;     // direction A → B, counter-clockwise from +x
  double transmission_rad = 0.0;      // acute angle between the coupler and the slider line's normal
  double coupler_rate_rad_s = 0.0;    // d(coupler angle)/dt
  double coupler_accel_rad_s2 = 0.0;  // d²(coupler angle)/dt²
};

// RT-safe (no allocation, no throw). Slider state at crank angle θ turning at ω with acceleration α.
// Requires a mechanism accepted by validate_slider_crank; then every output is finite.
SliderState slider_state(const SliderCrank& m, double theta_rad, double omega_rad_s,
                         double alpha_rad_s2) noexcept;

// RT-safe (no allocation, no throw). Position and θ-derivatives of the point `local` on the coupler
// (origin at the crank pin A, x towards the slider pin B) at crank angle θ; point_motion() gives its
// velocity and acceleration. Requires a mechanism accepted by validate_slider_crank.
PointCoefficients slider_coupler_point(const SliderCrank& m, double theta_rad,
                                       const Eigen::Vector2d& local) noexcept;

struct SliderDeadCentres {
  double theta_extended_rad = 0.0;       // crank angle, crank and coupler extended in line, [0, 2π)
  double theta_folded_rad = 0.0;         // crank angle, crank folded back over the coupler, [0, 2π)
  double x_extended = 0.0;               // slider position at the extended dead centre (farthest)
  double x_folded = 0.0;                 // slider position at the folded dead centre (nearest)
  double stroke = 0.0;                   // x_extended − x_folded
  double phi_extend_to_fold_rad = 0.0;   // counter-clockwise crank travel, extended → folded
  double phi_fold_to_extend_rad = 0.0;   // counter-clockwise crank travel, folded → extended
  double phi_half_difference_rad = 0.0;  // (extend→fold − fold→extend)/2, sign of the offset. Kept
                                         // apart: π ± a tiny value rounds it away (φ → 180°).
  double time_ratio = 1.0;               // longer over shorter of the two travels (≥ 1)
  double mu_min_rad = 0.0;               // minimum transmission angle over a turn
  double theta_mu_min_rad = 0.0;         // crank angle where it occurs
};

// configure-time only. Throws as validate_slider_crank, except that the change-point limit
// b = a + |e| (within 1e-12·b) is accepted: its dead centres exist, μ_min = 0. Closed forms written so
// that a long coupler (b ≫ a, stroke a small difference of large lengths) keeps full accuracy.
SliderDeadCentres slider_dead_centres(const SliderCrank& m);

}  // namespace loom::motion
