// The core axes (beat crank, carriage, helix) against the drives they name (axes.<name>.drive): what each
// drive gives at the axis — its output shaft, the carriage's through its belt pulley — and what the loom's
// motion asks of it. Their limits stay the mechanisms' keys; these figures say whether the drive delivers
// them (a config that asks more is refused) and which limit binds (loomctl check). Configure time only.
#pragma once

#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/motion/profile_set.hpp"

namespace loom::firmware {

// A drive as the axis sees it, in the axis' units (rad or m). A rotary axis sits on the output shaft; the
// carriage's lead_m is its travel per motor turn, so per output turn it travels gear_ratio x lead_m:
// speed = motor_speed / (2 pi) x lead, force = 2 pi x motor torque x efficiency / lead, mass = (rotor +
// gear) x (2 pi / lead)^2.
struct DriveAtAxis {
  double top_speed = 0.0;     // rad/s or m/s: the no-load speed at the output
  double peak_effort = 0.0;   // N m or N
  double rated_effort = 0.0;  // N m or N, continuous
  double inertia = 0.0;       // kg m^2 or kg: the drive's rotor and gears referred to the axis
};
DriveAtAxis drive_at_axis(const motion::ServoDrive& d, const AxisSpec& a);

// One core axis with a drive: the drive at the axis, and the speed and acceleration its motion asks.
struct CoreDriveFit {
  std::string axis;   // axes.<axis>
  std::string model;  // drives.<model>
  hal::AxisRole role = hal::AxisRole::kBeatCrank;
  DriveAtAxis at{};
  double need_speed = 0.0;  // the fastest the axis is asked to turn (rad/s) or travel (m/s)
  std::string speed_key, speed_value, speed_what;  // the key that asks it, its value, how it follows
  double need_accel = 0.0;                         // its acceleration limit
  std::string accel_key, accel_value;
  double load_inertia =
      0.0;                // kg m^2 or kg the loom moves besides the drive's own: the carriage, the shuttle
  std::string load_what;  // what it is ("" = none)
  std::string load_key, load_value;  // the key that states it ("" = none)
  double load_effort = 0.0;  // N m or N the mechanism asks at need_speed: the beat-up linkage's peak torque
  double load_rms_effort = 0.0;  // its rms over a turn, against the drive's continuous torque
  std::string load_effort_what;  // what it is ("" = none)
  // At the top of its acceleration ramp the axis, at need_speed, still accelerates everything it moves
  // and carries its mechanism's load: the effort that asks.
  double need_effort() const noexcept { return (at.inertia + load_inertia) * need_accel + load_effort; }
  // What the drive gives at need_speed: its torque-speed line, the peak at standstill falling linearly to
  // 0 at the no-load speed (the line the knot cycle is planned under). A speed at the no-load speed
  // leaves nothing to accelerate with, or to carry a load.
  double line_effort() const noexcept {
    // (within rounding of the no-load speed: 6000 rpm x 20 mm is 1.0 m/s less a few ulp)
    return need_speed >= at.top_speed * (1.0 - 1e-12) ? 0.0
                                                      : at.peak_effort * (1.0 - need_speed / at.top_speed);
  }
};
// The core axes that name a drive, in slot order; `set` is the profile set built from `c`.
std::vector<CoreDriveFit> core_drive_fits(const LoomConfig& c, const motion::ProfileSet& set);
// How need_effort() is made up, in words (for loomctl check and the config's refusals).
std::string effort_parts(const CoreDriveFit& f, const char* effort);

}  // namespace loom::firmware
