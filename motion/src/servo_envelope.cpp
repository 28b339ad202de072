// The torque–speed line and the bang-bang move under it: drive on the line (an exponential approach to
// ω∞), cruise at the cap if one is reached, brake at the peak torque. Planning finds the switching instant
// by bisection on "distance covered + braking distance = the move"; evaluation is closed form.
#include "loom/motion/servo_envelope.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

// Driving phase from rest, x = t/τc: distance ω∞τc·(x − (1 − e^(−x))), written so that it keeps
// its digits for small x (where it is ~x²/2).
double drive_distance(double w_inf, double tau, double t) noexcept {
  const double x = t / tau;
  const double g = x < 1e-3 ? x * x * (0.5 - x * (1.0 / 6.0 - x / 24.0)) : x + std::expm1(-x);
  return w_inf * tau * g;
}
double drive_speed(double w_inf, double tau, double t) noexcept {
  return -w_inf * std::expm1(-t / tau);
}

}  // namespace

void validate(const ServoDrive& d, const char* what) {
  const auto positive = [&](double v, const char* field) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      std::ostringstream os;
      os << what << ": " << field << " = " << v << ": must be finite and > 0";
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
  };
  positive(d.motor_speed_rad_s, "motor speed");
  positive(d.motor_rated_torque_nm, "rated torque");
  positive(d.motor_peak_torque_nm, "peak torque");
  positive(d.gear_ratio, "gear ratio");
  for (const auto& [v, field] :
       {std::pair{d.rotor_inertia_kg_m2, "rotor inertia"}, std::pair{d.gear_inertia_kg_m2, "gear inertia"}}) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      std::ostringstream os;
      os << what << ": " << field << " = " << v << ": must be finite and >= 0";
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
  }
  if (!(d.gear_efficiency > 0.0 && d.gear_efficiency <= 1.0)) {
    std::ostringstream os;
    os << what << ": gear efficiency = " << d.gear_efficiency << ": must be in (0, 1]";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  if (d.motor_rated_torque_nm > d.motor_peak_torque_nm) {
    std::ostringstream os;
    os << what << ": rated torque " << d.motor_rated_torque_nm << " N m exceeds the peak torque "
       << d.motor_peak_torque_nm << " N m";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
}

double TorqueSpeedLine::available_nm(double omega, double torque_sign) const noexcept {
  const double along = torque_sign * omega;  // > 0: the torque drives the motion
  if (along <= 0.0) return peak_torque_nm;   // braking (or at rest): the line lies above the peak
  return std::max(0.0, peak_torque_nm * (1.0 - along / no_load_speed_rad_s));
}

EnvelopeLimits EnvelopeMove::limits_for(const TorqueSpeedLine& line, double inertia_kg_m2, double load_nm,
                                        double share, double speed_cap_rad_s) {
  const double usable = share * line.peak_torque_nm;
  if (!(usable > load_nm)) {
    std::ostringstream os;
    os << "the load torque " << load_nm << " N m takes the drive's whole " << usable << " N m";
    throw MotionError(ErrorCode::kOutOfBounds, os.str());
  }
  // J·a + L ≤ s·τp(1 − ω/ω0) is the line (s·τp − L)(1 − ω/ω∞) with ω∞ = ω0(1 −
  // L/(s·τp)).
  EnvelopeLimits l;
  l.stall_accel = (usable - load_nm) / inertia_kg_m2;
  l.asymptote_speed = line.no_load_speed_rad_s * (1.0 - load_nm / usable);
  l.brake_decel = l.stall_accel;  // J·b + L ≤ s·τp
  l.speed_cap = speed_cap_rad_s;
  return l;
}

EnvelopeMove EnvelopeMove::plan(double distance, const EnvelopeLimits& l) noexcept {
  EnvelopeMove m;
  m.distance_ = distance;
  m.sign_ = distance < 0.0 ? -1.0 : 1.0;
  m.a0_ = l.stall_accel;
  m.w_inf_ = l.asymptote_speed;
  m.tau_ = l.asymptote_speed / l.stall_accel;
  m.b_ = l.brake_decel;
  const double d = std::fabs(distance);
  if (!(d > 0.0)) return m;
  const double w = m.w_inf_, tau = m.tau_, b = m.b_;
  // Covered by the end of braking if the drive stops driving at t.
  const auto reach = [&](double t) {
    const double v = drive_speed(w, tau, t);
    return drive_distance(w, tau, t) + v * v / (2.0 * b);
  };
  const bool capped = l.speed_cap > 0.0 && l.speed_cap < w;
  const double t_cap = capped ? -tau * std::log1p(-l.speed_cap / w) : 0.0;
  if (capped && reach(t_cap) <= d) {
    // Reaches the cap: drive to it, cruise, brake.
    const double v = l.speed_cap;
    m.t_switch_ = t_cap;
    m.p_switch_ = drive_distance(w, tau, t_cap);
    m.peak_speed_ = v;
    const double cruise = (d - reach(t_cap)) / v;
    m.t_cruise_end_ = t_cap + cruise;
    m.p_cruise_end_ = m.p_switch_ + v * cruise;
    m.t_brake_end_ = m.t_cruise_end_ + v / b;
    return m;
  }
  // reach() rises from 0; reach(d/ω∞ + τc) ≥ ω∞(d/ω∞) = d bounds the switching instant.
  double lo = 0.0, hi = capped ? t_cap : d / w + tau;
  for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (reach(mid) < d ? lo : hi) = mid;
  }
  const double ts = hi;
  const double v = drive_speed(w, tau, ts);
  m.t_switch_ = ts;
  m.p_switch_ = drive_distance(w, tau, ts);
  m.peak_speed_ = v;
  m.t_cruise_end_ = ts;
  m.p_cruise_end_ = m.p_switch_;
  m.t_brake_end_ = ts + v / b;
  return m;
}

MoveSample EnvelopeMove::at(double t) const noexcept {
  MoveSample s;
  if (!(t > 0.0)) return s;  // at rest at the start (NaN too)
  if (t >= t_brake_end_) {
    s.position = distance_;
    return s;
  }
  double p = 0.0, v = 0.0, a = 0.0;
  if (t < t_switch_) {
    p = drive_distance(w_inf_, tau_, t);
    v = drive_speed(w_inf_, tau_, t);
    a = a0_ * std::exp(-t / tau_);
  } else if (t < t_cruise_end_) {
    p = p_switch_ + peak_speed_ * (t - t_switch_);
    v = peak_speed_;
  } else {
    const double u = t - t_cruise_end_;
    p = p_cruise_end_ + peak_speed_ * u - 0.5 * b_ * u * u;
    v = peak_speed_ - b_ * u;
    a = -b_;
  }
  // The braking parabola ends at |distance| to rounding; never overshoot it.
  s.position = sign_ * std::min(p, std::fabs(distance_));
  s.velocity = sign_ * std::max(v, 0.0);
  s.acceleration = sign_ * a;
  return s;
}

}  // namespace loom::motion
