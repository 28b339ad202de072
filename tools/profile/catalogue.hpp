// The profiles the accuracy report measures, each with its exact kinematics: the rocker (beater
// angle) on crank phase, the elliptic crank law, the carriage cam over one turn, and the helix pick
// over its duration, and the knotting servo over one knot cycle. Built from the default loom so the numbers
// are the ones the machine plays.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "loom/motion/knot_cycle.hpp"
#include "loom/motion/phase_table.hpp"
#include "loom/motion/profile_set.hpp"

namespace loom::profile {

struct ReportProfile {
  std::string name;  // the CSV's `profile`
  std::string unit;  // SI unit of the value (errors are in it; /s and /s² for vel and acc)
  std::string what;  // one line for the summary
  // What a table must meet to qualify as the default: the position error bound, and velocity and
  // acceleration errors below kVelocityShare / kAccelerationShare of the profile's peaks (they feed
  // drive feed-forward and the beat-force estimate, where 1e-5 and 1e-3 are far below noise).
  double requirement = 0.0;
  double peak_vel = 0.0;  // max |dvalue/dt| over the turn at phase_rate (unit/s)
  double peak_acc = 0.0;  // max |d²value/dt²| (unit/s²)
  static constexpr double kVelocityShare = 1e-5;
  static constexpr double kAccelerationShare = 1e-3;
  double vel_requirement() const { return kVelocityShare * peak_vel; }
  double acc_requirement() const { return kAccelerationShare * peak_acc; }
  double phase_rate = 0.0;  // dφ/dt (rad/s) at which velocity and acceleration errors are stated
  double rise = 0.0;        // value gained per turn of phase
  std::function<motion::PhaseExact(double)> exact;  // phase in [0, 2π) → exact value and derivatives
  std::function<double(double)> closed_form;        // what the loop would compute without a table (timed)
};

struct Catalogue {
  std::shared_ptr<const motion::ProfileSet> set;  // owns what the profiles' functions refer to
  std::shared_ptr<const motion::KnotCycle> knot;  // seed 001's knot cycle (the knotting servo)
  std::vector<ReportProfile> profiles;
};

// Configure-time only. The default loom with the elliptic crank law (e = 0.2, one lobe), which
// leaves every table other than the crank law's identical to the constant-law loom's.
Catalogue default_catalogue();

// The default profile set (constant crank law) and the elliptic one, for build-time measurements.
motion::ProfileSpec default_spec();
motion::ProfileSpec elliptic_spec();

}  // namespace loom::profile
