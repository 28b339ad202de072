// What a servo drive can do at its output, as a drive is sold (motor speed and torque, rotor inertia, a
// gearbox), and the time-optimal rest-to-rest move of a rigid inertia within it.  The envelope is the
// torque–speed line: driving (torque along the motion) the drive gives at most τ_peak·(1 − |ω|/ω_0),
// falling linearly from its peak torque at standstill to nothing at the no-load speed ω_0 (the back-EMF eats
// the supply voltage); braking (torque against the motion) the line lies above the peak, so the peak torque
// caps it. A move of an inertia J within it accelerates on the line and brakes at the peak: ω(t) = ω∞(1
// − e^(−t/τc)) with τc = ω∞/a₀, then a constant deceleration b to rest. That is the bang-bang
// solution (the fastest move with acceleration bounded above by a function of ω that falls with ω and below
// by a constant), so it is time-optimal. An optional speed cap below ω∞ inserts a cruise.
#pragma once

#include "loom/motion/jerk_move.hpp"

namespace loom::motion {

// A drive as sold, and what it gives at its output shaft. SI: rad/s, N m, kg m².
struct ServoDrive {
  double motor_speed_rad_s = 0.0;      // no-load (maximum) motor speed: the line's zero
  double motor_rated_torque_nm = 0.0;  // continuous
  double motor_peak_torque_nm = 0.0;   // short-time, at standstill
  double rotor_inertia_kg_m2 = 0.0;    // the motor's rotor
  double gear_ratio = 1.0;             // motor turns per output turn (1 = direct drive)
  double gear_inertia_kg_m2 = 0.0;     // the gearbox, referred to its input (motor) shaft
  double gear_efficiency = 1.0;        // torque out / (torque in · ratio)

  double output_speed_rad_s() const noexcept { return motor_speed_rad_s / gear_ratio; }
  double output_peak_torque_nm() const noexcept {
    return motor_peak_torque_nm * gear_ratio * gear_efficiency;
  }
  double output_rated_torque_nm() const noexcept {
    return motor_rated_torque_nm * gear_ratio * gear_efficiency;
  }
  // Rotor and gearbox reflected to the output: (J_rotor + J_gear)·i².
  double output_inertia_kg_m2() const noexcept {
    return (rotor_inertia_kg_m2 + gear_inertia_kg_m2) * gear_ratio * gear_ratio;
  }
};

// Configure-time: throws MotionError(kInvalidInput) naming the first fact that is not finite and positive
// (inertias may be 0, the efficiency lies in (0, 1]).
void validate(const ServoDrive& d, const char* what);

// The torque–speed line at the output. RT-safe.
struct TorqueSpeedLine {
  double no_load_speed_rad_s = 0.0;  // ω_0
  double peak_torque_nm = 0.0;       // τ_peak
  // The largest |τ| the drive gives at speed ω with torque of sign `torque_sign` (+1 / −1): on the line
  // when τ drives along ω, the peak when it brakes; 0 at or beyond the no-load speed when driving.
  double available_nm(double omega, double torque_sign) const noexcept;
};

// The move's bounds for one rigid inertia under the line (see EnvelopeMove::limits_for).
struct EnvelopeLimits {
  double stall_accel = 0.0;      // a₀: acceleration from standstill (> 0)
  double asymptote_speed = 0.0;  // ω∞: where the driving acceleration falls to 0 (> 0)
  double brake_decel = 0.0;      // b: deceleration while braking (> 0)
  double speed_cap = 0.0;        // cruise speed cap; 0 or >= ω∞ = none
};

class EnvelopeMove {
 public:
  EnvelopeMove() = default;

  // Configure-time. The bounds of an inertia `inertia_kg_m2` under `line` at `share` of its torque, with a
  // load torque of at most `load_nm` in either direction at any speed (gravity, the velocity-squared term of
  // a linkage): a₀ = (s·τp − L)/J, ω∞ = ω_0 (1 − L/(s·τp)), b = a₀. Throws
  // MotionError(kOutOfBounds) when the load takes the whole torque.
  static EnvelopeLimits limits_for(const TorqueSpeedLine& line, double inertia_kg_m2, double load_nm,
                                   double share, double speed_cap_rad_s);

  // Configure-time (a bisection for the switching instant; never throws): the fastest rest-to-rest move
  // of `distance` (signed) within `limits` (all finite and > 0, validated beforehand).
  static EnvelopeMove plan(double distance, const EnvelopeLimits& limits) noexcept;

  // RT-safe (no allocation, bounded: one exp). Offset from the start at t (s); clamped outside
  // [0, duration] (before: at rest at 0; after: at rest at `distance`).
  MoveSample at(double t) const noexcept;

  double duration() const noexcept { return t_brake_end_; }
  double distance() const noexcept { return distance_; }
  double peak_velocity() const noexcept { return sign_ * peak_speed_; }  // signed
  bool cruises() const noexcept { return t_cruise_end_ > t_switch_; }    // reached the speed cap
  double switch_time() const noexcept { return t_switch_; }              // end of the driving phase
  double brake_time() const noexcept { return t_cruise_end_; }           // braking starts

 private:
  double distance_ = 0.0, sign_ = 1.0;
  double a0_ = 0.0, w_inf_ = 0.0, tau_ = 0.0, b_ = 0.0;
  double t_switch_ = 0.0;      // driving phase ends (cap reached, or braking starts)
  double t_cruise_end_ = 0.0;  // == t_switch_ without a cruise
  double t_brake_end_ = 0.0;
  double p_switch_ = 0.0, p_cruise_end_ = 0.0;  // unsigned positions there
  double peak_speed_ = 0.0;
};

}  // namespace loom::motion
