// The knot cycle: check the linkage against the precision points and plan each move time-optimally under
// the servo's torque–speed line. Everything here but sample() is configure-time; sample() evaluates the
// planned pieces.
#include "loom/motion/knot_cycle.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "checks.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

constexpr const char* kWho = "knot cycle";
// A precision point counts as reached when the linkage misses it by no more than this (1 µm: far
// below the yarn's diameter, far above the printed config's rounding).
constexpr double kPointTolerance_m = 1e-6;
// The gripper-link angle at a point must match to this (rad).
constexpr double kAngleTolerance_rad = 1e-6;
// Dense checks along the stroke and the return: crank-angle step (rad).
constexpr double kSweepStep_rad = 1e-3;
// Samples per move for the inertia and load bounds and for the envelope check of the planned move.
constexpr int kTorqueSamples = 2048;
// Moves are planned to this share of the peak torque: what the linkage's bounds miss between samples
// stays within the line itself (the planned move is checked densely and re-planned lower if not).
constexpr double kTorquePlanShare = 0.995;
// The in-warp window is widened by this much gripper travel in x (m) each side: the jaws have width.
constexpr double kWarpMargin_m = 1e-3;
constexpr int kPathSamples = 256;

using Eigen::Vector2d;

Vector2d unit(double a) {
  return {std::cos(a), std::sin(a)};
}

// As detail::fail (the message "knot cycle: <what>"), with the spec fact it is about.
[[noreturn]] void fail(ErrorCode code, const std::string& what,
                       KnotCycleField field = KnotCycleField::kLinkage) {
  throw KnotCycleError(code, field, std::string(kWho) + ": " + what);
}

std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

void require_finite(const char* field, double v) {
  detail::require_finite(kWho, field, v, "");
}
void require_positive(const char* field, double v, KnotCycleField about = KnotCycleField::kLinkage) {
  if (!std::isfinite(v) || !(v > 0.0))
    fail(ErrorCode::kInvalidInput, std::string(field) + " = " + num(v) + ": must be finite and > 0", about);
}
void require_non_negative(const char* field, double v) {
  if (!std::isfinite(v) || !(v >= 0.0))
    fail(ErrorCode::kInvalidInput, std::string(field) + " = " + num(v) + ": must be finite and >= 0");
}

void check_link(const char* name, const KnotLinkSpec& l) {
  const std::string n(name);
  require_positive((n + ".length_m").c_str(), l.length_m);
  require_non_negative((n + ".mass_kg").c_str(), l.mass_kg);
  require_finite((n + ".cg_m").c_str(), l.cg_m);
  require_non_negative((n + ".inertia_kg_m2").c_str(), l.inertia_kg_m2);
}

void check_spec(const KnotCycleSpec& s) {
  static constexpr std::array<const char*, 3> kNames{"points[take]", "points[wrap]", "points[pull]"};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string n(kNames[i]);
    require_finite((n + ".x_m").c_str(), s.points[i].x_m);
    require_finite((n + ".y_m").c_str(), s.points[i].y_m);
    require_finite((n + ".gripper_rad").c_str(), s.points[i].gripper_rad);
  }
  require_finite("theta0_rad", s.theta0_rad);
  require_finite("crank_pivot_x_m", s.crank_pivot_x_m);
  require_finite("crank_pivot_y_m", s.crank_pivot_y_m);
  require_finite("rocker_pivot_x_m", s.rocker_pivot_x_m);
  require_finite("rocker_pivot_y_m", s.rocker_pivot_y_m);
  check_link("crank", s.crank);
  check_link("coupler", s.coupler);
  check_link("rocker", s.rocker);
  require_finite("gripper_along_m", s.gripper_along_m);
  require_finite("gripper_normal_m", s.gripper_normal_m);
  if (s.branch != Branch::kPositive && s.branch != Branch::kNegative) {
    fail(ErrorCode::kInvalidInput,
         "branch = " + std::to_string(static_cast<int>(s.branch)) + ": must be positive or negative");
  }
  if (!std::isfinite(s.warp_entry_x_m)) {  // detail::require_finite's words, with the field
    std::ostringstream os;
    os << "warp_entry_x_m = " << s.warp_entry_x_m << ": must be finite";
    fail(ErrorCode::kInvalidInput, os.str(), KnotCycleField::kWarpEntry);
  }
  if (!std::isfinite(s.min_transmission_rad) || s.min_transmission_rad < 0.0 ||
      s.min_transmission_rad >= kPi / 2) {
    fail(ErrorCode::kInvalidInput,
         "min_transmission_rad = " + num(s.min_transmission_rad) + ": must be in [0, pi/2)",
         KnotCycleField::kMinTransmission);
  }
  require_non_negative("gravity_m_s2", s.gravity_m_s2);
  require_positive("no_load_speed_rad_s", s.no_load_speed_rad_s);
  require_positive("peak_torque_nm", s.peak_torque_nm, KnotCycleField::kMaxTorque);
  require_positive("continuous_torque_nm", s.continuous_torque_nm, KnotCycleField::kMaxTorque);
  require_non_negative("rotor_inertia_kg_m2", s.rotor_inertia_kg_m2);
  require_non_negative("max_speed_rad_s", s.max_speed_rad_s);
  require_non_negative("grip_s", s.grip_s);
  require_non_negative("cut_s", s.cut_s);
  require_non_negative("release_s", s.release_s);
  const double pivots =
      std::hypot(s.rocker_pivot_x_m - s.crank_pivot_x_m, s.rocker_pivot_y_m - s.crank_pivot_y_m);
  if (!(pivots > 0.0))
    fail(ErrorCode::kInvalidInput, "crank and rocker pivots coincide: the ground link has no length");
  if (std::hypot(s.gripper_along_m, s.gripper_normal_m) >
      1e3 * std::max({pivots, s.crank.length_m, s.coupler.length_m, s.rocker.length_m})) {
    fail(ErrorCode::kInvalidInput,
         "gripper_along_m/gripper_normal_m: the gripper is over 1000 link lengths off the coupler");
  }
}

const char* point_name(std::size_t i) {
  static constexpr std::array<const char*, 3> kPoint{"TAKE", "WRAP", "PULL"};
  return kPoint[i];
}

const char* branch_name(Branch b) {
  return b == Branch::kPositive ? "positive" : "negative";
}

}  // namespace

const char* knot_limit_name(KnotLimit l) {
  switch (l) {
    case KnotLimit::kDwell:
      return "dwell";
    case KnotLimit::kSpeedCap:
      return "speed cap";
    case KnotLimit::kTorqueSpeedLine:
      return "torque-speed line";
  }
  return "?";
}

KnotLinkSpec delrin_link(double length_m) {
  constexpr double kDelrinKgM3 = 1415.9, kW = 0.006, kH = 0.005;
  const double m = kW * kH * length_m * kDelrinKgM3;
  return {length_m, m, 0.5 * length_m, m * (kW * kW + length_m * length_m) / 12.0};
}

KnotCycleSpec seed001_knot_cycle_spec() {
  KnotCycleSpec s;
  // Seed 001's precision points (mm → m) and θ0 = 275°.
  s.points = {KnotPoint{0.0, 0.0, rad(10.0)}, KnotPoint{0.025, 0.015, rad(3.0)},
              KnotPoint{0.030, 0.001, rad(-25.0)}};
  s.theta0_rad = rad(275.0);
  // The two real chains of the three-point synthesis: (a0, a1, a2) = (1.255712, 17.165528, 17.229329)
  // and (23.285522, 37.525177, 31.525943) mm. Ground pivots a0·u(θ0); the servo drives the 17.17 mm
  // side link (the 37.5 mm one would rest 0.08° from its limit at TAKE, μ = 175.8°).
  s.crank_pivot_x_m = 0.000109442513498;
  s.crank_pivot_y_m = -0.00125093365343;
  s.rocker_pivot_x_m = 0.00202946697058;
  s.rocker_pivot_y_m = -0.0231969136205;
  // Delrin (ρ = 1.4159 g/cm³), 6 × 5 mm section: m = 30 mm² · L · ρ, I_G = m (6² + L²)/12 (the seed's
  // formulas, on the correct lengths).
  s.crank = delrin_link(0.0171655277145);
  s.rocker = delrin_link(0.0375251765985);
  // The coupler carries both moving pivots and the gripper on one line (B — A — gripper, 31.53 mm end
  // to end, the long chain's last link). The seed's link with holder and gripper: 1.641 g,
  // I_G = 208.94e-9 kg m², cg 19.30 mm from the far end of its 32.637 mm link, i.e. 13.337 mm from the
  // gripper: at −17.229 + 13.337 mm along the coupler.
  s.coupler = {0.0142966138382, 0.001641, -0.0172293288072 + 0.013337, 208.94e-9};
  s.gripper_along_m = -0.0172293288072;
  s.gripper_normal_m = 0.0;
  s.branch = Branch::kPositive;
  // The warp pair is wrapped at x = 25 mm; the gripper's 5 mm jaws are in the warp sheet from 20 mm.
  s.warp_entry_x_m = 0.020;
  // 30°: below it the joint forces grow as 1/sin μ past twice their best; the design has 38.2° at TAKE.
  s.min_transmission_rad = rad(30.0);
  s.gravity_m_s2 = 9.81;
  // The shipped head's drive (shipped_knotter_drive), no speed cap below what it can reach.
  set_servo(s, shipped_knotter_drive());
  s.max_speed_rad_s = 0.0;
  // Gripper jaws (a second micro servo or a solenoid) close in 150 ms; the hot-wire/blade cut 100 ms;
  // the jaws open in 100 ms.
  s.grip_s = 0.15;
  s.cut_s = 0.10;
  s.release_s = 0.10;
  return s;
}

ServoDrive shipped_knotter_drive() {
  // A 100 W, 40 mm-flange AC servo motor of the common 200 V class (the figures its makers' catalogues
  // share to a few per cent): 3000 rpm rated, 6000 rpm maximum, 0.32 N m rated and 0.95 N m peak torque,
  // rotor 0.051 kg cm² without brake; behind a 40 mm single-stage 10:1 precision planetary gearbox
  // (0.03 kg cm² at its input, 95 % efficient at full load). At the output: 62.8 rad/s no-load, 9.03 N m
  // peak, 3.04 N m continuous, 8.1e-4 kg m².
  ServoDrive d;
  d.motor_speed_rad_s = 6000.0 * 2.0 * kPi / 60.0;
  d.motor_rated_torque_nm = 0.32;
  d.motor_peak_torque_nm = 0.95;
  d.rotor_inertia_kg_m2 = 0.051e-4;
  d.gear_ratio = 10.0;
  d.gear_inertia_kg_m2 = 0.03e-4;
  d.gear_efficiency = 0.95;
  return d;
}

void set_servo(KnotCycleSpec& spec, const ServoDrive& d) {
  spec.no_load_speed_rad_s = d.output_speed_rad_s();
  spec.peak_torque_nm = d.output_peak_torque_nm();
  spec.continuous_torque_nm = d.output_rated_torque_nm();
  spec.rotor_inertia_kg_m2 = d.output_inertia_kg_m2();
}

KnotCycle::Dynamics KnotCycle::dynamics_at(double crank_abs_rad) const {
  const double t2 = crank_abs_rad - ground_angle_;
  const FourBarPose pose = solve(fourbar_, t2, spec_.branch);
  const double cg = std::cos(ground_angle_), sg = std::sin(ground_angle_);
  auto to_knot = [&](const Vector2d& v) {
    return Vector2d(cg * v.x() - sg * v.y(), sg * v.x() + cg * v.y());
  };
  Dynamics d;
  const KnotLinkSpec& cr = spec_.crank;
  const KnotLinkSpec& cp = spec_.coupler;
  const KnotLinkSpec& rk = spec_.rocker;
  const double g = spec_.gravity_m_s2;
  // Crank: pure rotation about its pivot at the servo's own speed.
  d.inertia_kg_m2 = spec_.rotor_inertia_kg_m2 + cr.inertia_kg_m2 + cr.mass_kg * cr.cg_m * cr.cg_m;
  d.gravity_nm = cr.mass_kg * g * cr.cg_m * std::cos(crank_abs_rad);
  // Coupler and rocker: m|P'|² + I k² (kinetic energy per ω²·2), its θ-derivative, and m g P'_y.
  auto add_body = [&](FourBarLink link, const KnotLinkSpec& l, double k, double kp) {
    const PointCoefficients c = point_coefficients(fourbar_, pose, link, Vector2d(l.cg_m, 0.0));
    d.inertia_kg_m2 += l.mass_kg * c.d1.squaredNorm() + l.inertia_kg_m2 * k * k;
    d.dinertia += 2.0 * (l.mass_kg * c.d1.dot(c.d2) + l.inertia_kg_m2 * k * kp);
    d.gravity_nm += l.mass_kg * g * to_knot(c.d1).y();
  };
  add_body(FourBarLink::kCoupler, cp, pose.k3, pose.k3p);
  add_body(FourBarLink::kRocker, rk, pose.k4, pose.k4p);
  const PointCoefficients grip = point_coefficients(fourbar_, pose, FourBarLink::kCoupler,
                                                    Vector2d(spec_.gripper_along_m, spec_.gripper_normal_m));
  const Vector2d p = to_knot(grip.position);
  d.gripper_x_m = spec_.crank_pivot_x_m + p.x();
  d.gripper_y_m = spec_.crank_pivot_y_m + p.y();
  d.transmission_rad = pose.transmission;
  return d;
}

double KnotCycle::torque_at(double crank_abs_rad, double omega, double alpha) const {
  const Dynamics d = dynamics_at(crank_abs_rad);
  return d.inertia_kg_m2 * alpha + 0.5 * d.dinertia * omega * omega + d.gravity_nm;
}

KnotCycle::Sample KnotCycle::sample(double t_s) const noexcept {
  // NaN → the rest pose; +inf → the end (at rest, end_offset from TAKE).
  const double t = std::isnan(t_s) ? 0.0 : std::clamp(t_s, 0.0, duration_);
  for (const Piece& p : pieces_) {
    if (t < p.t1 || &p == &pieces_.back()) {
      const MoveSample m = p.move.at(t - p.t0);
      return {p.start_rad + m.position, m.velocity, m.acceleration};
    }
  }
  return {};
}

namespace {

// Where a sweep from `from` over `distance` (signed) stops being usable, if it does.
struct SweepResult {
  bool ok = true;
  double stopped_at = 0.0;        // absolute crank angle of the first bad sample
  bool unreachable = false;       // the loop does not close there (beyond the crank's range)
  bool toggle = false;            // coupler and rocker in line there
  double min_transmission = kPi;  // min over the sweep of min(μ, π − μ)
  double min_at = 0.0;
};

}  // namespace

KnotCycle KnotCycle::build(const KnotCycleSpec& spec) {
  check_spec(spec);
  KnotCycle kc;
  kc.spec_ = spec;
  const Vector2d a0(spec.crank_pivot_x_m, spec.crank_pivot_y_m);
  const Vector2d b0(spec.rocker_pivot_x_m, spec.rocker_pivot_y_m);
  kc.fourbar_ = FourBar{(b0 - a0).norm(), spec.crank.length_m, spec.coupler.length_m, spec.rocker.length_m};
  kc.ground_angle_ = std::atan2(b0.y() - a0.y(), b0.x() - a0.x());
  const FourBar& fb = kc.fourbar_;
  KnotCycleReport& rep = kc.report_;
  rep.grashof = classify(fb);
  if (rep.grashof == GrashofClass::kChangePoint) {
    fail(ErrorCode::kSingular,
         "the linkage is a change-point four-bar (s + l = p + q): its branches meet at the flat pose");
  }

  // --- The precision points: the linkage must put the gripper there with the coupler line at the
  // gripper angle (mod π: the synthesis' last links lie along θ2 either way round, but the same way
  // at all three points, since the coupler is one rigid body).
  const Vector2d grip_local(spec.gripper_along_m, spec.gripper_normal_m);
  std::array<double, 3> crank_abs{};
  std::array<Branch, 3> branch_at{};
  int flip = -1;
  for (std::size_t i = 0; i < 3; ++i) {
    const KnotPoint& pt = spec.points[i];
    double best = std::numeric_limits<double>::infinity();
    int best_flip = 0;
    Vector2d best_a, best_b;
    for (int f = 0; f < 2; ++f) {
      const double th3 = pt.gripper_rad + f * kPi;
      const Vector2d u = unit(th3), n(-u.y(), u.x());
      const Vector2d a = Vector2d(pt.x_m, pt.y_m) - grip_local.x() * u - grip_local.y() * n;
      const Vector2d b = a + spec.coupler.length_m * u;
      const double miss = std::max(std::fabs((a - a0).norm() - spec.crank.length_m),
                                   std::fabs((b - b0).norm() - spec.rocker.length_m));
      if (miss < best) {
        best = miss;
        best_flip = f;
        best_a = a;
        best_b = b;
      }
    }
    if (!(best <= kPointTolerance_m)) {
      std::ostringstream os;
      os << "the linkage misses " << point_name(i) << " (" << pt.x_m << ", " << pt.y_m
         << ") m with the gripper link at " << deg(pt.gripper_rad) << " deg by " << best << " m (more than "
         << kPointTolerance_m
         << " m): crank/rocker pivots, link lengths or gripper offset do not belong to these points";
      fail(ErrorCode::kNotAssemblable, os.str());
    }
    if (flip >= 0 && best_flip != flip) {
      std::ostringstream os;
      os << "at " << point_name(i)
         << " the coupler would have to be turned half a turn against the other points to hold the "
         << "gripper link at " << deg(pt.gripper_rad) << " deg: no rigid coupler passes all three points";
      fail(ErrorCode::kNotAssemblable, os.str());
    }
    flip = best_flip;
    rep.closure_residual_m = std::max(rep.closure_residual_m, best);
    crank_abs[i] = std::atan2(best_a.y() - a0.y(), best_a.x() - a0.x());
    const double th3 = std::atan2(best_b.y() - best_a.y(), best_b.x() - best_a.x());
    const double th4 = std::atan2(best_b.y() - b0.y(), best_b.x() - b0.x());
    branch_at[i] = branch_of(th3, th4);
  }
  // Cross-check with the position solution itself: the coupler angle it gives matches the gripper angle.
  for (std::size_t i = 0; i < 3; ++i) {
    if (branch_at[i] != spec.branch) {
      std::ostringstream os;
      os << "branch defect: " << point_name(i) << " lies on the " << branch_name(branch_at[i])
         << " assembly branch, the spec says " << branch_name(spec.branch) << " (TAKE "
         << branch_name(branch_at[0]) << ", WRAP " << branch_name(branch_at[1]) << ", PULL "
         << branch_name(branch_at[2]) << "): the linkage would have to be taken apart between the points";
      fail(ErrorCode::kWrongBranch, os.str());
    }
    const FourBarPosition pos = solve_position(fb, crank_abs[i] - kc.ground_angle_, spec.branch);
    const double th3_knot = pos.theta3 + kc.ground_angle_;
    const double err = std::fabs(wrap_pi(th3_knot - (spec.points[i].gripper_rad + flip * kPi)));
    if (!(err <= kAngleTolerance_rad)) {
      std::ostringstream os;
      os << "at " << point_name(i) << " the coupler stands at " << deg(th3_knot)
         << " deg, not along the gripper angle " << deg(spec.points[i].gripper_rad) << " deg";
      fail(ErrorCode::kNotAssemblable, os.str());
    }
  }
  rep.crank_angles_rad = crank_abs;
  kc.take_angle_ = crank_abs[0];

  // --- Order: the direction in which WRAP comes before PULL, turning one way from TAKE.
  auto ahead = [&](double s, std::size_t i) { return wrap_two_pi(s * (crank_abs[i] - crank_abs[0])); };
  double dir = ahead(1.0, 1) < ahead(1.0, 2) ? 1.0 : -1.0;
  const double to_wrap = ahead(dir, 1), to_pull = ahead(dir, 2);
  if (!(to_wrap > 0.0) || !(to_pull > to_wrap)) {
    fail(ErrorCode::kOutOfBounds, "order defect: two precision points share a crank angle (TAKE " +
                                      num(deg(crank_abs[0])) + ", WRAP " + num(deg(crank_abs[1])) +
                                      ", PULL " + num(deg(crank_abs[2])) + " deg)");
  }

  auto sweep = [&](double from, double distance, double min_transmission) {
    SweepResult r;
    const int n = std::max(8, static_cast<int>(std::ceil(std::fabs(distance) / kSweepStep_rad)));
    for (int k = 0; k <= n; ++k) {
      const double th = from + distance * k / n;
      FourBarPosition pos;
      try {
        pos = solve_position(fb, th - kc.ground_angle_, spec.branch);
      } catch (const MotionError&) {
        r.ok = false;
        r.unreachable = true;
        r.stopped_at = th;
        return r;
      }
      const double dev = std::min(pos.transmission, kPi - pos.transmission);
      if (dev < r.min_transmission) {
        r.min_transmission = dev;
        r.min_at = th;
      }
      if (pos.at_toggle || dev < min_transmission) {
        r.ok = false;
        r.toggle = pos.at_toggle || dev < std::asin(kNearToggleSine);
        r.stopped_at = th;
        return r;
      }
    }
    return r;
  };

  const SweepResult stroke = sweep(crank_abs[0], dir * to_pull, spec.min_transmission_rad);
  auto what_stops = [&](const SweepResult& r) {
    if (r.unreachable) return std::string("the end of its range (a dead centre: the loop cannot close)");
    if (r.toggle) return std::string("a toggle (coupler and rocker in line)");
    return "a transmission angle of " + num(deg(r.min_transmission)) +
           " deg (below min_transmission_rad = " + num(deg(spec.min_transmission_rad)) + " deg)";
  };
  if (!stroke.ok) {
    // Stopped by the transmission angle (not a dead centre or toggle): the minimum is the fact to change.
    const KnotCycleField stopped_by =
        stroke.unreachable || stroke.toggle ? KnotCycleField::kLinkage : KnotCycleField::kMinTransmission;
    // The other way round: would the points be reachable there (order defect) or not at all?
    const SweepResult other = sweep(crank_abs[0], -dir * ahead(-dir, 1), spec.min_transmission_rad);
    std::ostringstream os;
    if (other.ok && other.min_transmission >= spec.min_transmission_rad) {
      os << "order defect: turning from TAKE (" << deg(crank_abs[0]) << " deg) towards WRAP the crank meets "
         << what_stops(stroke) << " at " << deg(stroke.stopped_at) << " deg; the other way it reaches PULL ("
         << deg(crank_abs[2]) << " deg) before WRAP (" << deg(crank_abs[1]) << " deg)";
      fail(ErrorCode::kOutOfBounds, os.str(), stopped_by);
    }
    os << "the stroke TAKE→WRAP→PULL (" << deg(crank_abs[0]) << " → " << deg(crank_abs[1]) << " → "
       << deg(crank_abs[2]) << " deg) meets " << what_stops(stroke) << " at crank angle "
       << deg(stroke.stopped_at) << " deg";
    fail(ErrorCode::kSingular, os.str(), stopped_by);
  }
  rep.stroke_rad = dir * to_pull;
  rep.min_transmission_rad = stroke.min_transmission;
  rep.min_transmission_at_rad = stroke.min_at;

  // --- The return: on through the turn when the crank turns fully, else back along the stroke.
  rep.full_turn = rep.grashof == GrashofClass::kCrankRocker || rep.grashof == GrashofClass::kDoubleCrank;
  double back = -rep.stroke_rad;
  if (rep.full_turn) {
    back = dir * (kTwoPi - to_pull);
    const SweepResult ret = sweep(crank_abs[2], back, std::asin(kNearToggleSine));
    if (!ret.ok) {
      fail(ErrorCode::kSingular, "the full-turn return from PULL passes a toggle at crank angle " +
                                     num(deg(ret.stopped_at)) + " deg");
    }
    rep.min_transmission_return_rad = ret.min_transmission;
  } else {
    rep.min_transmission_return_rad = stroke.min_transmission;
  }
  kc.end_offset_ = rep.stroke_rad + back;

  // --- Can the servo hold the links at all? (gravity alone, at the points)
  for (std::size_t i = 0; i < 3; ++i) {
    const double hold = std::fabs(kc.dynamics_at(crank_abs[i]).gravity_nm);
    if (!(hold < spec.peak_torque_nm)) {
      fail(ErrorCode::kOutOfBounds,
           "peak_torque_nm = " + num(spec.peak_torque_nm) + ": holding the links against gravity at " +
               point_name(i) + " takes " + num(hold) + " N m",
           KnotCycleField::kMaxTorque);
    }
  }

  // --- The moves: each the time-optimal move under the torque–speed line for the largest inertia the
  // linkage reflects over its sweep and the largest load torque there (½|J'|ω² at the no-load speed plus
  // |dV/dθ|), so that J(θ)α + ½J'ω² + dV/dθ stays within the line at every pose. Checked densely
  // after.
  const TorqueSpeedLine line{spec.no_load_speed_rad_s, spec.peak_torque_nm};
  auto plan = [&](double start_rel, double distance) {
    const double start_abs = kc.take_angle_ + start_rel;
    double j_max = 0.0, load = 0.0;
    const double w0 = spec.no_load_speed_rad_s;
    for (int k = 0; k <= kTorqueSamples; ++k) {
      const Dynamics d = kc.dynamics_at(start_abs + distance * k / kTorqueSamples);
      j_max = std::max(j_max, d.inertia_kg_m2);
      load = std::max(load, 0.5 * std::fabs(d.dinertia) * w0 * w0 + std::fabs(d.gravity_nm));
    }
    // What the drive has left at the speed and torque of a sample, as a share of what it gives there.
    auto margin_of = [&](const EnvelopeMove& mv, double t) {
      const MoveSample m = mv.at(t);
      const double tau = kc.torque_at(start_abs + m.position, m.velocity, m.acceleration);
      const double avail = line.available_nm(m.velocity, tau < 0.0 ? -1.0 : 1.0);
      return avail > 0.0 ? (avail - std::fabs(tau)) / avail : -1.0;
    };
    double share = kTorquePlanShare;
    EnvelopeMove move;
    for (int attempt = 0; attempt < 8; ++attempt, share *= 0.99) {
      EnvelopeLimits lim;
      try {
        lim = EnvelopeMove::limits_for(line, j_max, load, share, spec.max_speed_rad_s);
      } catch (const MotionError& e) {
        fail(ErrorCode::kOutOfBounds,
             "peak_torque_nm = " + num(spec.peak_torque_nm) + ": moving the linkage from " +
                 num(deg(start_rel)) + " deg past TAKE by " + num(deg(distance)) + " deg: " + e.what(),
             KnotCycleField::kMaxTorque);
      }
      move = EnvelopeMove::plan(distance, lim);
      // A top speed so small (a denormal no-load speed or cap) that the move never ends: a typed error,
      // never an infinite cycle (its samples would be NaN).
      if (!std::isfinite(move.duration())) {
        fail(ErrorCode::kOutOfBounds,
             "moving the linkage by " + num(deg(distance)) + " deg at the drive's top speed (no-load " +
                 num(spec.no_load_speed_rad_s) + " rad/s, cap " + num(spec.max_speed_rad_s) +
                 " rad/s) takes no finite time",
             KnotCycleField::kMaxTorque);
      }
      double worst = 1.0;
      const double T = move.duration();
      for (int k = 0; k <= 4 * kTorqueSamples; ++k)
        worst = std::min(worst, margin_of(move, T * (k + 0.5) / (4 * kTorqueSamples + 1)));
      if (worst >= 0.0) break;
    }
    return move;
  };
  auto bound_of = [&](const EnvelopeMove& m) {
    return m.cruises() ? KnotLimit::kSpeedCap : KnotLimit::kTorqueSpeedLine;
  };

  const double d1 = dir * to_wrap, d2 = dir * (to_pull - to_wrap);
  const EnvelopeMove m1 = plan(0.0, d1);
  const EnvelopeMove m2 = plan(d1, d2);
  const EnvelopeMove m3 = plan(rep.stroke_rad, back);

  struct Seg {
    const char* name;
    double dt;
    double start;
    const EnvelopeMove* move;
  };
  const std::array<Seg, 6> segs{{{"grip", spec.grip_s, 0.0, nullptr},
                                 {"take_to_wrap", m1.duration(), 0.0, &m1},
                                 {"wrap_to_pull", m2.duration(), d1, &m2},
                                 {"cut", spec.cut_s, rep.stroke_rad, nullptr},
                                 {"release", spec.release_s, rep.stroke_rad, nullptr},
                                 {"return", m3.duration(), rep.stroke_rad, &m3}}};
  double t = 0.0;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    Piece& pc = kc.pieces_[i];
    pc.t0 = t;
    pc.t1 = t + segs[i].dt;
    pc.start_rad = segs[i].start;
    KnotCycleReport::Segment& rs = rep.segments[i];
    rs.name = segs[i].name;
    rs.begin_s = pc.t0;
    rs.end_s = pc.t1;
    rs.switch_s = rs.brake_s = pc.t0;
    if (segs[i].move != nullptr) {
      rs.switch_s = pc.t0 + segs[i].move->switch_time();
      rs.brake_s = pc.t0 + segs[i].move->brake_time();
      pc.move = *segs[i].move;
      rs.distance_rad = pc.move.distance();
      rs.peak_speed_rad_s = std::fabs(pc.move.peak_velocity());
      rs.bound = bound_of(pc.move);
    }
    t = pc.t1;
  }
  kc.duration_ = t;
  if (!(kc.duration_ > 0.0)) fail(ErrorCode::kInvalidInput, "the cycle has no duration");

  // --- Windows.
  const double t_pull = kc.pieces_[3].t0, t_cut_end = kc.pieces_[3].t1, t_release_end = kc.pieces_[4].t1;
  kc.gripper_closed_ = {0.0, t_cut_end};
  kc.cutter_ = {t_pull, t_cut_end};
  kc.yarn_sample_ = {t_pull, t_release_end};

  // In the warp: from the geometry along the exact motion, x ≥ entry − margin, crossings by bisection.
  const double entry = spec.warp_entry_x_m - kWarpMargin_m;
  auto grip_x = [&](double tt) {
    return kc.dynamics_at(kc.take_angle_ + kc.exact(tt).angle_rad).gripper_x_m;
  };
  if (!(spec.points[1].x_m >= spec.warp_entry_x_m) || !(spec.points[0].x_m < entry)) {
    fail(ErrorCode::kInvalidInput,
         "warp_entry_x_m = " + num(spec.warp_entry_x_m) + ": must lie between TAKE x (" +
             num(spec.points[0].x_m) + " m, outside the warp by " + num(kWarpMargin_m) + " m) and WRAP x (" +
             num(spec.points[1].x_m) + " m, inside)",
         KnotCycleField::kWarpEntry);
  }
  {
    const int n = 4096;
    int first = -1, last = -1;
    for (int k = 0; k <= n; ++k) {
      if (grip_x(kc.duration_ * k / n) >= entry) {
        if (first < 0) first = k;
        last = k;
      }
    }
    auto crossing = [&](double lo, double hi, bool rising) {  // grip_x(lo) < entry ≤ grip_x(hi) if rising
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        const bool in = grip_x(mid) >= entry;
        if (in == rising)
          hi = mid;
        else
          lo = mid;
      }
      return rising ? lo : hi;  // the outer bound: the window errs on the safe side
    };
    const double h = kc.duration_ / n;
    const double begin = first > 0 ? crossing((first - 1) * h, first * h, true) : 0.0;
    const double end = last < n ? crossing(last * h, (last + 1) * h, false) : kc.duration_;
    kc.in_warp_ = {begin, end};
  }

  // --- Peak and rms torque, the envelope margin, inertia range and the gripper path.
  const double T = kc.duration_;
  rep.min_inertia_kg_m2 = std::numeric_limits<double>::infinity();
  rep.envelope_margin = 1.0;
  double sum_sq = 0.0;
  const int n_torque = 16 * kTorqueSamples;
  for (int k = 0; k <= n_torque; ++k) {
    const double tt = T * k / n_torque;
    const Sample e = kc.sample(tt);
    const Dynamics d = kc.dynamics_at(kc.take_angle_ + e.angle_rad);
    const double tau = d.inertia_kg_m2 * e.accel_rad_s2 +
                       0.5 * d.dinertia * e.velocity_rad_s * e.velocity_rad_s + d.gravity_nm;
    if (std::fabs(tau) > std::fabs(rep.peak_torque_nm)) {
      rep.peak_torque_nm = tau;
      rep.peak_torque_t_s = tt;
      rep.peak_torque_angle_rad = e.angle_rad;
    }
    if (k > 0) sum_sq += tau * tau;
    rep.peak_speed_rad_s = std::max(rep.peak_speed_rad_s, std::fabs(e.velocity_rad_s));
    const double avail = line.available_nm(e.velocity_rad_s, tau < 0.0 ? -1.0 : 1.0);
    rep.envelope_margin =
        std::min(rep.envelope_margin, avail > 0.0 ? (avail - std::fabs(tau)) / avail : -1.0);
    rep.max_inertia_kg_m2 = std::max(rep.max_inertia_kg_m2, d.inertia_kg_m2);
    rep.min_inertia_kg_m2 = std::min(rep.min_inertia_kg_m2, d.inertia_kg_m2);
  }
  rep.rms_torque_nm = std::sqrt(sum_sq / n_torque);
  if (rep.rms_torque_nm > spec.continuous_torque_nm) {
    fail(ErrorCode::kOutOfBounds,
         "continuous_torque_nm = " + num(spec.continuous_torque_nm) +
             ": knot after knot the cycle's rms torque is " + num(rep.rms_torque_nm) +
             " N m: the motor would overheat",
         KnotCycleField::kMaxTorque);
  }
  rep.path.reserve(kPathSamples);
  for (int k = 0; k < kPathSamples; ++k) {
    const double tt = T * k / (kPathSamples - 1);
    const double a = kc.exact(tt).angle_rad;
    const Dynamics d = kc.dynamics_at(kc.take_angle_ + a);
    rep.path.push_back({tt, a, d.gripper_x_m, d.gripper_y_m});
  }
  return kc;
}

}  // namespace loom::motion
