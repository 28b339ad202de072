// The loom's beat-up head: a crank-rocker whose rocker carries the beater at a fixed arm. Maps the crank
// phase to the beater's motion, finds the fell (the dead centre where the beater reaches the cloth) and
// the crank-phase window in which the beater's teeth are inside the warp. Phases are measured from the
// park phase, the middle of the clear window, where the crank rests between rows.
#pragma once

#include <cstdint>

#include "loom/motion/angles.hpp"
#include "loom/motion/fourbar.hpp"

namespace loom::motion {

enum class FellSide : std::uint8_t { kExtended, kFolded };

struct BeatUpGeometry {
  FourBar bar;  // thesis Table 5.1 by default (see default_beatup_geometry)
  Branch branch = Branch::kPositive;
  double beater_arm_m = 0.301;             // beater tip distance from the rocker pivot B0
  FellSide fell_at = FellSide::kExtended;  // the dead centre at which the beater meets the fell
  double warp_depth_m = 0.05;  // tip arc distance from the fell inside which the teeth are in the warp
};

// Thesis Table 5.1 / DESIGN.md: crank 0.058, coupler 0.189, rocker 0.232, ground 0.213, arm 0.301 m.
BeatUpGeometry default_beatup_geometry();

struct BeaterState {
  double rocker_angle = 0.0;  // θ4 (rad)
  double d1 = 0.0;            // dθ4/dφ
  double d2 = 0.0;            // d²θ4/dφ²
  double from_fell_m = 0.0;   // tip arc distance from the fell position (≥ 0)
  bool in_warp = false;
};

struct WarpWindow {
  double enter = 0.0;  // phase (rad, in (0, 2π)) where the teeth enter the warp, moving toward the fell
  double fell = 0.0;   // phase of the fell dead centre
  double exit = 0.0;   // phase where the teeth leave the warp; enter < fell < exit
  double clear() const { return kTwoPi - (exit - enter); }  // length of the clear window
};

class BeatUp {
 public:
  // Configure-time only. Throws MotionError when the linkage is not a crank-rocker (kNotCrank), or the
  // warp depth is not inside the beater's stroke (kInvalidInput, naming both numbers).
  explicit BeatUp(const BeatUpGeometry& g);

  // Exact evaluation (configure-time and tests; it solves the linkage). Phase from park, any real.
  BeaterState at(double phase) const;

  // Crank angle θ2 of the linkage at phase 0 (the park pose): θ2 = park_crank_angle() + phase.
  double park_crank_angle() const { return park_theta2_; }
  const WarpWindow& warp() const { return warp_; }
  const DeadCentres& dead_centres() const { return dc_; }
  const BeatUpGeometry& geometry() const { return g_; }
  double stroke_arc_m() const { return g_.beater_arm_m * dc_.swing; }

 private:
  double from_fell(double theta4) const;

  BeatUpGeometry g_;
  DeadCentres dc_;
  double fell_theta2_ = 0.0;
  double fell_theta4_ = 0.0;
  double park_theta2_ = 0.0;
  WarpWindow warp_;
};

}  // namespace loom::motion
