// Beat-up inverse dynamics. The 9×9 system is made dimensionless (moment rows and the torque unknown
// divided by the longest link) so its condition number measures geometry, not units: that is what
// lets a fixed threshold separate "near toggle, large but finite forces" from "singular".
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "loom/motion/dynamics.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

[[noreturn]] void invalid(const std::string& what) {
  throw MotionError(ErrorCode::kInvalidInput, "beat-up dynamics: " + what);
}

void require_finite(const char* what, double v) {
  if (!std::isfinite(v)) {
    std::ostringstream os;
    os << what << " = " << v << ": must be finite";
    invalid(os.str());
  }
}

void require_body(const char* what, const PlanarInertia& b) {
  if (!(b.mass_kg >= 0.0) || !std::isfinite(b.mass_kg) || !(b.inertia_kg_m2 >= 0.0) ||
      !std::isfinite(b.inertia_kg_m2) || !b.centre_m.allFinite()) {
    std::ostringstream os;
    os << what << " mass properties (m = " << b.mass_kg << " kg, I = " << b.inertia_kg_m2
       << " kg m^2): must be finite and non-negative";
    invalid(os.str());
  }
}

// Coefficients of r × F on (Fx, Fy).
inline void put_moment_arm(Eigen::Matrix<double, 9, 9>& a, int row, int col, const Eigen::Vector2d& r,
                           double scale) {
  a(row, col) = -r.y() * scale;
  a(row, col + 1) = r.x() * scale;
}

// Golden-section search for the maximum of a unimodal f on [lo, hi].
template <class F>
std::pair<double, double> golden_max(F&& f, double lo, double hi) {
  const double inv_phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - inv_phi * (hi - lo), x2 = lo + inv_phi * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < 200 && hi - lo > 1e-13; ++i) {
    if (f1 < f2) {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + inv_phi * (hi - lo);
      f2 = f(x2);
    } else {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - inv_phi * (hi - lo);
      f1 = f(x1);
    }
  }
  const double x = 0.5 * (lo + hi);
  return {x, f(x)};
}

// Dense samples of f over [lo, hi], then golden refinement around the best sample.
template <class F>
std::pair<double, double> sampled_max(F&& f, double lo, double hi, int n) {
  int best = 0;
  double best_v = -1.0;
  for (int i = 0; i <= n; ++i) {
    const double x = lo + (hi - lo) * i / n;
    const double v = f(x);
    if (v > best_v) {
      best_v = v;
      best = i;
    }
  }
  const double step = (hi - lo) / n;
  const double a = std::max(lo, lo + (best - 1) * step), b = std::min(hi, lo + (best + 1) * step);
  const auto refined = golden_max(f, a, b);
  return refined.second >= best_v ? refined : std::pair{lo + best * step, best_v};
}

}  // namespace

std::array<BodyMotion, 3> four_bar_motion(const FourBar& m, const FourBarPose& p, double w2, double a2) {
  std::array<BodyMotion, 3> b;
  BodyMotion& crank = b[0];
  crank.angle_rad = p.theta2;
  crank.omega_rad_s = w2;
  crank.alpha_rad_s2 = a2;
  const Eigen::Vector2d a_pin = m.crank * Eigen::Vector2d(std::cos(p.theta2), std::sin(p.theta2));
  BodyMotion& coupler = b[1];
  coupler.angle_rad = p.theta3;
  coupler.omega_rad_s = p.k3 * w2;
  coupler.alpha_rad_s2 = p.k3 * a2 + p.k3p * w2 * w2;
  coupler.origin_m = a_pin;
  coupler.origin_vel_m_s = w2 * Eigen::Vector2d(-a_pin.y(), a_pin.x());
  coupler.origin_acc_m_s2 = a2 * Eigen::Vector2d(-a_pin.y(), a_pin.x()) - w2 * w2 * a_pin;
  BodyMotion& rocker = b[2];
  rocker.angle_rad = p.theta4;
  rocker.omega_rad_s = p.k4 * w2;
  rocker.alpha_rad_s2 = p.k4 * a2 + p.k4p * w2 * w2;
  rocker.origin_m = {m.ground, 0.0};
  return b;
}

FourBarForces four_bar_forces(const FourBar& m, const FourBarInertias& in, const FourBarPose& pose, double w2,
                              double a2, const Eigen::Vector2d& g, const RockerLoad& load) {
  require_finite("crank speed (rad/s)", w2);
  require_finite("crank acceleration (rad/s^2)", a2);
  if (!g.allFinite()) invalid("gravity vector must be finite");
  if (!load.force_n.allFinite() || !load.at_m.allFinite()) invalid("rocker load must be finite");
  for (const double v : {pose.theta2, pose.theta3, pose.theta4, pose.k3, pose.k4, pose.k3p, pose.k4p}) {
    require_finite("four-bar pose", v);
  }
  require_body("crank", in.crank);
  require_body("coupler", in.coupler);
  require_body("rocker", in.rocker);

  const std::array<BodyMotion, 3> mo = four_bar_motion(m, pose, w2, a2);
  const std::array<const PlanarInertia*, 3> body{&in.crank, &in.coupler, &in.rocker};
  std::array<Eigen::Vector2d, 3> gc, acc;
  for (int i = 0; i < 3; ++i) {
    gc[i] = mo[i].point(body[i]->centre_m);
    acc[i] = mo[i].acceleration(body[i]->centre_m);
  }
  const Eigen::Vector2d a0(0.0, 0.0);
  const Eigen::Vector2d pa = mo[0].point({m.crank, 0.0});
  const Eigen::Vector2d pb = mo[2].point({m.rocker, 0.0});
  const Eigen::Vector2d b0 = mo[2].origin_m;
  const Eigen::Vector2d p_load = mo[2].point(load.at_m);

  // Unknowns: F_a0 (0,1), F_a (2,3), F_b (4,5), F_b0 (6,7), T/L (8). Rows per link: x, y, moment/L
  // about its centre of mass.
  const double L = std::max({m.ground, m.crank, m.coupler, m.rocker, load.at_m.norm()});
  const double s = 1.0 / L;
  Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 1> rhs;
  // Crank: F_a0 − F_a = m a − m g; (A0−G)×F_a0 − (A−G)×F_a + T = I α.
  A(0, 0) = 1;
  A(0, 2) = -1;
  A(1, 1) = 1;
  A(1, 3) = -1;
  put_moment_arm(A, 2, 0, a0 - gc[0], s);
  put_moment_arm(A, 2, 2, -(pa - gc[0]), s);
  A(2, 8) = 1.0;
  // Coupler: F_a − F_b = m a − m g; (A−G)×F_a − (B−G)×F_b = I α.
  A(3, 2) = 1;
  A(3, 4) = -1;
  A(4, 3) = 1;
  A(4, 5) = -1;
  put_moment_arm(A, 5, 2, pa - gc[1], s);
  put_moment_arm(A, 5, 4, -(pb - gc[1]), s);
  // Rocker: F_b + F_b0 = m a − m g − F_load; (B−G)×F_b + (B0−G)×F_b0 = I α − (P−G)×F_load.
  A(6, 4) = 1;
  A(6, 6) = 1;
  A(7, 5) = 1;
  A(7, 7) = 1;
  put_moment_arm(A, 8, 4, pb - gc[2], s);
  put_moment_arm(A, 8, 6, b0 - gc[2], s);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2d f = body[i]->mass_kg * (acc[i] - g);
    rhs(3 * i) = f.x();
    rhs(3 * i + 1) = f.y();
    rhs(3 * i + 2) = body[i]->inertia_kg_m2 * mo[i].alpha_rad_s2 * s;
  }
  rhs(6) -= load.force_n.x();
  rhs(7) -= load.force_n.y();
  rhs(8) -= cross2(p_load - gc[2], load.force_n) * s;

  const Eigen::PartialPivLU<Eigen::Matrix<double, 9, 9>> lu(A);
  FourBarForces f;
  // Exact 1-norm reciprocal condition from the explicit inverse (9×9 is cheap); a singular matrix
  // gives inf/NaN entries and so fails the test below.
  const Eigen::Matrix<double, 9, 9> inv = lu.inverse();
  f.rcond = 1.0 / (A.cwiseAbs().colwise().sum().maxCoeff() * inv.cwiseAbs().colwise().sum().maxCoeff());
  if (!(f.rcond > kSingularRcond)) {
    std::ostringstream os;
    os << "four-bar force system is singular at crank angle " << deg(pose.theta2)
       << " deg (reciprocal condition " << f.rcond << "; coupler and rocker in line?)";
    throw MotionError(ErrorCode::kSingular, os.str());
  }
  const Eigen::Matrix<double, 9, 1> x = lu.solve(rhs);
  if (!x.allFinite()) {
    throw MotionError(ErrorCode::kSingular, "four-bar force system produced non-finite forces");
  }
  f.pin_a0_n = x.segment<2>(0);
  f.pin_a_n = x.segment<2>(2);
  f.pin_b_n = x.segment<2>(4);
  f.pin_b0_n = x.segment<2>(6);
  f.crank_torque_nm = x(8) * L;
  return f;
}

BeatUpDynamics::BeatUpDynamics(const BeatUpGeometry& g, const BeatUpMasses& m, const Options& o)
    : head_(g), masses_(m), opt_(o) {
  require_body("crank", m.crank);
  require_body("coupler", m.coupler);
  require_body("rocker", m.rocker);
  if (!(m.beater_kg >= 0.0) || !std::isfinite(m.beater_kg) || !m.beater_at_m.allFinite()) {
    std::ostringstream os;
    os << "beater mass " << m.beater_kg << " kg: must be finite and >= 0, at a finite place";
    invalid(os.str());
  }
  if (!o.gravity_m_s2.allFinite()) invalid("gravity vector must be finite");
  if (!(o.near_toggle_rad >= 0.0) || !(o.near_toggle_rad < 0.5 * kPi)) {
    std::ostringstream os;
    os << "near-toggle threshold = " << deg(o.near_toggle_rad) << " deg: must be in [0, 90)";
    invalid(os.str());
  }
  inertias_ = {m.crank, m.coupler, m.rocker_with_beater()};
  bodies_ = {inertias_.crank, inertias_.coupler, inertias_.rocker};
  const DeadCentres& dc = head_.dead_centres();
  const bool ext = g.fell_at == FellSide::kExtended;
  fell_theta4_ = ext ? dc.rocker_extended : dc.rocker_folded;
  const double other = ext ? dc.rocker_folded : dc.rocker_extended;
  away_sign_ = wrap_pi(other - fell_theta4_) >= 0.0 ? 1.0 : -1.0;
}

std::array<BodyMotion, 3> BeatUpDynamics::motion(const CrankMotion& c) const {
  const FourBarPose p = solve(head_.geometry().bar, c.theta_rad, head_.geometry().branch);
  return four_bar_motion(head_.geometry().bar, p, c.omega_rad_s, c.alpha_rad_s2);
}

double BeatUpDynamics::kinetic_energy(const CrankMotion& c) const {
  const std::array<BodyMotion, 3> mo = motion(c);
  double e = 0.0;
  for (int i = 0; i < 3; ++i) e += loom::motion::kinetic_energy(bodies_[i], mo[i]);
  return e;
}

double BeatUpDynamics::potential_energy(double theta2) const {
  const std::array<BodyMotion, 3> mo = motion({theta2, 0.0, 0.0});
  double e = 0.0;
  for (int i = 0; i < 3; ++i) e += loom::motion::potential_energy(bodies_[i], mo[i], opt_.gravity_m_s2);
  return e;
}

Eigen::Vector2d BeatUpDynamics::contact_force(const CrankMotion& c, const BeatContact& contact) const {
  if (contact.force_n == 0.0) return Eigen::Vector2d::Zero();
  const BeatUpGeometry& g = head_.geometry();
  const FourBarPose p = solve(g.bar, c.theta_rad, g.branch);
  const double from_fell = g.beater_arm_m * std::abs(wrap_pi(p.theta4 - fell_theta4_));
  const bool advancing = away_sign_ * p.k4 * c.omega_rad_s < 0.0;
  if (!(from_fell < g.warp_depth_m) || !advancing) return Eigen::Vector2d::Zero();
  // Along the tip's path, away from the fell: the direction of increasing θ4 times away_sign.
  BodyMotion rocker;
  rocker.angle_rad = p.theta4;
  const Eigen::Vector2d r = rocker.rotate(masses_.beater_at_m);
  const double n = r.norm();
  if (n <= 0.0) return Eigen::Vector2d::Zero();
  return contact.force_n * away_sign_ * Eigen::Vector2d(-r.y(), r.x()) / n;
}

BeatUpSample BeatUpDynamics::inverse(const CrankMotion& c, const BeatContact& contact) const {
  require_finite("crank angle (rad)", c.theta_rad);
  require_finite("crank speed (rad/s)", c.omega_rad_s);
  require_finite("crank acceleration (rad/s^2)", c.alpha_rad_s2);
  require_finite("contact force (N)", contact.force_n);
  const BeatUpGeometry& g = head_.geometry();
  const FourBarPose p = solve(g.bar, c.theta_rad, g.branch);
  const std::array<BodyMotion, 3> mo = four_bar_motion(g.bar, p, c.omega_rad_s, c.alpha_rad_s2);
  BeatUpSample s;
  s.crank = c;
  s.phase_rad = wrap_two_pi(c.theta_rad - head_.park_crank_angle());
  s.tip_m = mo[2].point(masses_.beater_at_m);
  s.tip_vel_m_s = mo[2].velocity(masses_.beater_at_m);
  s.tip_acc_m_s2 = mo[2].acceleration(masses_.beater_at_m);
  s.tip_acc_abs_m_s2 = s.tip_acc_m_s2.norm();
  s.beater_force_n = masses_.beater_kg * s.tip_acc_abs_m_s2;
  s.contact_force_n = contact_force(c, contact);
  s.forces = four_bar_forces(g.bar, inertias_, p, c.omega_rad_s, c.alpha_rad_s2, opt_.gravity_m_s2,
                             RockerLoad{s.contact_force_n, masses_.beater_at_m});
  s.transmission_rad = p.transmission;
  s.in_warp = g.beater_arm_m * std::abs(wrap_pi(p.theta4 - fell_theta4_)) < g.warp_depth_m;
  s.near_toggle = std::min(p.transmission, kPi - p.transmission) < opt_.near_toggle_rad;
  return s;
}

std::vector<BeatUpSample> BeatUpDynamics::sweep(double omega, int samples, const BeatContact& contact) const {
  if (samples < 1) invalid("samples = " + std::to_string(samples) + ": must be >= 1");
  require_finite("crank speed (rad/s)", omega);
  std::vector<BeatUpSample> out;
  out.reserve(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    out.push_back(inverse({kTwoPi * i / samples, omega, 0.0}, contact));
  }
  return out;
}

ReducedTerms BeatUpDynamics::reduced(double theta2) const {
  // At unit crank speed and zero crank acceleration, a point's velocity is ∂r/∂θ and its
  // acceleration is ∂²r/∂θ²; likewise a link's ω and α are ∂φ/∂θ and ∂²φ/∂θ².
  const std::array<BodyMotion, 3> mo = motion({theta2, 1.0, 0.0});
  ReducedTerms t;
  for (int i = 0; i < 3; ++i) {
    const PlanarInertia& b = bodies_[i];
    const Eigen::Vector2d j = mo[i].velocity(b.centre_m);
    const Eigen::Vector2d jp = mo[i].acceleration(b.centre_m);
    t.inertia_kg_m2 += b.mass_kg * j.squaredNorm() + b.inertia_kg_m2 * mo[i].omega_rad_s * mo[i].omega_rad_s;
    t.dinertia_kg_m2_rad +=
        2.0 * (b.mass_kg * j.dot(jp) + b.inertia_kg_m2 * mo[i].omega_rad_s * mo[i].alpha_rad_s2);
    t.gravity_torque_nm -= b.mass_kg * opt_.gravity_m_s2.dot(j);
  }
  return t;
}

double BeatUpDynamics::contact_generalized_force(const CrankMotion& c, const BeatContact& contact) const {
  const Eigen::Vector2d f = contact_force(c, contact);
  if (f.isZero(0.0)) return 0.0;
  const std::array<BodyMotion, 3> mo = motion({c.theta_rad, 1.0, 0.0});
  return f.dot(mo[2].velocity(masses_.beater_at_m));
}

BeatForcePeak BeatUpDynamics::peak_beat_force(double omega) const {
  if (!(omega > 0.0) || !std::isfinite(omega)) {
    std::ostringstream os;
    os << "crank speed = " << omega << " rad/s: must be finite and > 0";
    invalid(os.str());
  }
  const BeatUpGeometry& g = head_.geometry();
  const double mb = masses_.beater_kg;
  const Eigen::Vector2d tip = masses_.beater_at_m;
  const auto force = [&](double theta2) {
    const FourBarPose p = solve(g.bar, theta2, g.branch);
    return mb * four_bar_motion(g.bar, p, omega, 0.0)[2].acceleration(tip).norm();
  };
  const double park = head_.park_crank_angle();
  const WarpWindow& w = head_.warp();
  BeatForcePeak r;
  r.omega_rad_s = omega;
  const auto in_window = sampled_max(force, park + w.enter, park + w.exit, 720);
  r.crank_rad = wrap_two_pi(in_window.first);
  r.force_n = in_window.second;
  r.fell_force_n = force(park + w.fell);
  const auto turn = sampled_max(force, 0.0, kTwoPi, 1440);
  r.turn_max_crank_rad = wrap_two_pi(turn.first);
  r.turn_max_force_n = turn.second;
  return r;
}

double BeatUpDynamics::crank_speed_for_beat_force(double target_n) const {
  if (!(target_n > 0.0) || !std::isfinite(target_n)) {
    std::ostringstream os;
    os << "target beat force = " << target_n << " N: must be finite and > 0";
    invalid(os.str());
  }
  const double unit = peak_beat_force(1.0).force_n;  // N per (rad/s)²
  if (!(unit > 0.0)) invalid("the beater has no mass or never accelerates: no speed gives a beat force");
  return std::sqrt(target_n / unit);
}

}  // namespace loom::motion
