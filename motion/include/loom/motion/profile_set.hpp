// Every motion the loop plays, precomputed at configure time from the loom's geometry and limits:
// the beat-up head and its rocker table, the crank's speed law and beat sweep, the carriage cam with
// its checked peaks, the helix pick under the carrier's limit, and the shedding windows. Immutable
// once built (swap whole sets with ProfileSlot); the loop only samples it (RT-safe lookups).
#pragma once

#include <cstddef>

#include "loom/motion/beatup.hpp"
#include "loom/motion/carriage_cam.hpp"
#include "loom/motion/jerk_move.hpp"
#include "loom/motion/phase.hpp"
#include "loom/motion/phase_table.hpp"
#include "loom/motion/profile_carriage.hpp"
#include "loom/motion/profile_crank.hpp"
#include "loom/motion/profile_shed.hpp"

namespace loom::motion {

struct ProfileSpec {
  BeatUpGeometry beatup = default_beatup_geometry();
  double width_m = 1.2;          // weaving width
  double beater_width_m = 0.10;  // comb width (5–10 cm in handmade looms)
  double overlap_m = 0.02;       // overlap between neighbouring beats
  int beats_per_position = 1;    // beats at each carriage position before it steps on
  // The master phase's sweep (the crank itself with the constant law): rad/s, rad/s², rad/s³.
  JerkLimits crank{.velocity = 15.5, .acceleration = 400.0, .jerk = 2.0e4};
  CrankLawSpec crank_law{};        // constant speed, or the elliptic-gear law of seed 004
  double cam_margin_rad = 0.3491;  // 20°: carriage keeps this far from the warp boundaries
  double carriage_max_speed_m_s = 1.0;
  double carriage_max_accel_m_s2 = 20.0;
  double carriage_max_jerk_m_s3 = 2000.0;
  double helix_lead_m = 0.10;  // carrier travel per shaft turn
  JerkLimits helix{.velocity = 60.0, .acceleration = 3000.0, .jerk = 2.0e5};
  double carrier_force_n = 20.0;  // magnetic coupling force before the shuttle slips
  double shuttle_mass_kg = 0.40;
  ShedSpec shed{};
  // Every phase table (rocker, crank law): knots per turn, interpolation order, knot precision.
  // Chosen by `loom-profile report`'s own rule (tools/profile) for the 1e-9 rad target: 1024 cubic
  // double knots are the smallest with 10x margin for the rocker (6.6e-12 rad; 512 gives 1.06e-10,
  // no margin), 512 would do for the crank law; one size serves both. See motion/README.md.
  std::size_t table_size = 1024;
  Interp table_interp = Interp::kCubic;
  Precision table_precision = Precision::kDouble;
  // Each table's error is measured against the exact kinematics at every segment's midpoint (where
  // the interpolation error peaks) while the set is built; a table worse than this is refused.
  double max_table_error_rad = 1e-7;
};

class ProfileSet {
 public:
  // Configure-time only. Throws MotionError naming the limit when the recipe is infeasible (the crank
  // cannot reach full speed before the first beat, the carriage step breaks its limits, the shed
  // windows contradict each other, ...).
  explicit ProfileSet(const ProfileSpec& spec);

  // RT-safe accessors.
  const ProfileSpec& spec() const noexcept { return spec_; }
  const BeatUp& beatup() const noexcept { return beatup_; }
  const PhaseTable& rocker() const noexcept { return rocker_; }  // rocker angle θ4 vs crank phase from park
  const CrankLaw& crank_law() const noexcept { return crank_law_; }  // crank phase vs master phase
  const CarriageCam& cam() const noexcept { return cam_; }
  const CarriagePeaks& carriage_peaks() const noexcept {
    return carriage_peaks_;
  }  // per step, at cruise speed
  const JerkMove& crank_sweep() const noexcept {
    return sweep_;
  }                                                        // one row's beat sweep of the master: beats turns
  const JerkMove& pick() const noexcept { return pick_; }  // one pick, left → right (helix +)
  const JerkMove& pick_back() const noexcept { return pick_back_; }  // one pick, right → left (helix −)
  const ShedSpec& shed() const noexcept { return spec_.shed; }
  int beats_per_row() const noexcept { return beats_; }
  double pitch_m() const noexcept { return cam_.pitch(); }
  double carriage_travel_m() const noexcept { return spec_.width_m - spec_.beater_width_m; }
  double helix_accel_limit() const noexcept { return helix_.acceleration; }  // rad/s² after the carrier limit
  // The helix shaft's limits as every pick uses them (acceleration capped by the carrier).
  const JerkLimits& helix_limits() const noexcept { return helix_; }
  double shuttle_accel_limit_m_s2() const noexcept { return spec_.carrier_force_n / spec_.shuttle_mass_kg; }
  std::size_t table_bytes() const noexcept { return rocker_.bytes() + crank_law_.table().bytes(); }
  // Worst error of the rocker and crank-law tables at the segment midpoints, measured at build (rad).
  double rocker_table_error() const noexcept { return rocker_error_; }
  double crank_table_error() const noexcept { return crank_error_; }

  // RT-safe. Where the crank and the beater are at a master phase (sweep position from park);
  // the rocker's derivatives are with respect to the master phase (chain rule through the law).
  CrankSample crank_at(const Phase& master) const noexcept { return crank_law_.at(master); }
  double crank_phase_at(const Phase& master) const noexcept {
    return crank_law_.phase_at(master);
  }  // crank_at().phase
  PhaseSample rocker_at(const Phase& master) const noexcept;

 private:
  ProfileSpec spec_;
  BeatUp beatup_;
  PhaseTable rocker_;
  CrankLaw crank_law_;
  int beats_ = 0;
  CarriageCam cam_;
  CarriagePeaks carriage_peaks_;
  JerkMove sweep_;
  JerkMove pick_;
  JerkMove pick_back_;
  JerkLimits helix_{};
  double rocker_error_ = 0.0;
  double crank_error_ = 0.0;
};

}  // namespace loom::motion
