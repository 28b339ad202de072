// Every motion the loop plays, precomputed at configure time from the loom's geometry and limits:
// the beat-up head and its rocker table, the crank's beat sweep, the carriage cam, the helix pick.
// Immutable once built; the loop only samples it (RT-safe lookups).
#pragma once

#include <cstddef>

#include "loom/motion/beatup.hpp"
#include "loom/motion/carriage_cam.hpp"
#include "loom/motion/jerk_move.hpp"
#include "loom/motion/phase_table.hpp"

namespace loom::motion {

struct ProfileSpec {
  BeatUpGeometry beatup = default_beatup_geometry();
  double width_m = 1.2;              // weaving width
  double beater_width_m = 0.10;      // comb width (5–10 cm in handmade looms)
  double overlap_m = 0.02;           // overlap between neighbouring beats
  JerkLimits crank{.velocity = 15.5, .acceleration = 400.0, .jerk = 2.0e4};  // rad/s, rad/s², rad/s³
  double cam_margin_rad = 0.3491;    // 20°: carriage keeps this far from the warp boundaries
  double carriage_max_speed_m_s = 1.0;
  double carriage_max_accel_m_s2 = 20.0;
  double helix_lead_m = 0.10;        // carrier travel per shaft turn
  JerkLimits helix{.velocity = 60.0, .acceleration = 3000.0, .jerk = 2.0e5};
  double carrier_force_n = 20.0;     // magnetic coupling force before the shuttle slips
  double shuttle_mass_kg = 0.40;
  std::size_t table_size = 4096;
};

class ProfileSet {
 public:
  // Configure-time only. Throws MotionError naming the limit when the recipe is infeasible (the crank
  // cannot reach full speed before the first beat, the carriage step violates its limits, ...).
  explicit ProfileSet(const ProfileSpec& spec);

  const ProfileSpec& spec() const { return spec_; }
  const BeatUp& beatup() const { return beatup_; }
  const PhaseTable& rocker() const { return rocker_; }    // rocker angle θ4 vs crank phase from park
  const CarriageCam& cam() const { return cam_; }
  const JerkMove& crank_sweep() const { return sweep_; }  // one row's beat sweep: beats full turns
  const JerkMove& pick() const { return pick_; }            // one pick, left → right (helix +)
  const JerkMove& pick_back() const { return pick_back_; }  // one pick, right → left (helix −)
  int beats_per_row() const { return beats_; }
  double pitch_m() const { return cam_.pitch(); }
  double carriage_travel_m() const { return spec_.width_m - spec_.beater_width_m; }
  double helix_accel_limit() const { return helix_accel_; }  // rad/s² after the carrier limit

 private:
  ProfileSpec spec_;
  BeatUp beatup_;
  PhaseTable rocker_;
  int beats_ = 0;
  CarriageCam cam_;
  JerkMove sweep_;
  JerkMove pick_;
  JerkMove pick_back_;
  double helix_accel_ = 0.0;
};

}  // namespace loom::motion
