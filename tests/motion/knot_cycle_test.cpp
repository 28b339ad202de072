// The knot cycle against independent truth: seed 001's synthesis solved by a different elimination
// and its numbers written out, the four-bar's rigid-body closure from plain circle geometry, the
// rates against finite differences, the servo torque by the energy method (d/dt of kinetic plus
// potential energy = τω, from finite differences of the links' positions) within the torque–speed line,
// the moves' times against the bang-bang closed form of a rigid inertia, typed refusals.
#include "loom/motion/knot_cycle.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace {

using Eigen::Vector2d;
using loom::motion::Branch;
using loom::motion::ErrorCode;
using loom::motion::KnotCycle;
using loom::motion::KnotCycleSpec;
using loom::motion::KnotLimit;
using loom::motion::MotionError;
using loom::motion::rad;
using loom::motion::seed001_knot_cycle_spec;
using loom::motion::TorqueSpeedLine;

constexpr double kPi = 3.14159265358979323846;

Vector2d u(double a) {
  return {std::cos(a), std::sin(a)};
}

template <class F>
ErrorCode code_of(F&& f) {
  try {
    f();
  } catch (const MotionError& e) {
    return e.code();
  }
  ADD_FAILURE() << "no MotionError";
  return ErrorCode::kInvalidInput;
}

// Seed 001: θ0 = 275°, P = (0,0), (25,15), (30,1) mm, θ2 = 10°, 3°, −25°.
const std::array<std::array<double, 3>, 3> kPts{{{0, 0, 10}, {25, 15, 3}, {30, 1, -25}}};

struct Chain {
  double a0, a1, a2;
};

// Independent solve: loop equation i is |P_i − a0 u(θ0) − a2 u(θ2_i)|² = a1²; subtracting the first
// removes a1 and leaves two equations bilinear in (a0, a2); eliminating a2 leaves a quadratic in a0.
std::vector<Chain> eliminate() {
  const double th0 = rad(275);
  double R[2], X[2], Y[2], C[2];
  auto dot0 = [&](int i) { return kPts[i][0] * std::cos(th0) + kPts[i][1] * std::sin(th0); };
  auto dot2 = [&](int i) {
    return kPts[i][0] * std::cos(rad(kPts[i][2])) + kPts[i][1] * std::sin(rad(kPts[i][2]));
  };
  auto r2 = [&](int i) { return kPts[i][0] * kPts[i][0] + kPts[i][1] * kPts[i][1]; };
  auto cs = [&](int i) { return std::cos(rad(kPts[i][2]) - th0); };
  for (int j = 0; j < 2; ++j) {
    R[j] = r2(j + 1) - r2(0);
    X[j] = dot0(j + 1) - dot0(0);
    Y[j] = dot2(j + 1) - dot2(0);
    C[j] = cs(j + 1) - cs(0);
  }
  const double A = 4 * X[0] * C[1] - 4 * X[1] * C[0];
  const double B = -2 * R[0] * C[1] - 4 * X[0] * Y[1] + 2 * R[1] * C[0] + 4 * X[1] * Y[0];
  const double K = 2 * R[0] * Y[1] - 2 * R[1] * Y[0];
  std::vector<Chain> out;
  for (double s : {-1.0, 1.0}) {
    const double a0 = (-B + s * std::sqrt(B * B - 4 * A * K)) / (2 * A);
    const double a2 = (R[0] - 2 * a0 * X[0]) / (2 * Y[0] - 2 * a0 * C[0]);
    const Vector2d r = Vector2d(kPts[0][0], kPts[0][1]) - a0 * u(th0) - a2 * u(rad(kPts[0][2]));
    out.push_back({a0, r.norm(), a2});
  }
  std::sort(out.begin(), out.end(), [](const Chain& x, const Chain& y) { return x.a1 < y.a1; });
  return out;
}

TEST(KnotCycleSeed, SynthesisNumbersAndTheSharedCoupler) {
  const auto ch = eliminate();
  ASSERT_EQ(ch.size(), 2u);
  // Written out (mm): the two real chains through the seed's points.
  EXPECT_NEAR(ch[0].a0, 1.255712, 1e-6);
  EXPECT_NEAR(ch[0].a1, 17.165528, 1e-6);
  EXPECT_NEAR(ch[0].a2, 17.229329, 1e-6);
  EXPECT_NEAR(ch[1].a0, 23.285522, 1e-6);
  EXPECT_NEAR(ch[1].a1, 37.525177, 1e-6);
  EXPECT_NEAR(ch[1].a2, 31.525943, 1e-6);
  // The shared coupler: both moving pivots and the gripper move as one rigid body, and each side
  // link keeps its length at every point.
  const double th0 = rad(275);
  const std::array<double, 3> theta1_deg{-174.1791, 63.4044, 33.7328};  // chain 1's free link
  for (int i = 0; i < 3; ++i) {
    const Vector2d p(kPts[i][0], kPts[i][1]);
    const Vector2d m1 = p - ch[0].a2 * u(rad(kPts[i][2])), m2 = p - ch[1].a2 * u(rad(kPts[i][2]));
    EXPECT_NEAR((m1 - m2).norm(), 14.296614, 1e-5);
    EXPECT_NEAR((m1 - ch[0].a0 * u(th0)).norm(), ch[0].a1, 1e-9);
    EXPECT_NEAR((m2 - ch[1].a0 * u(th0)).norm(), ch[1].a1, 1e-9);
    const Vector2d f = m1 - ch[0].a0 * u(th0);
    EXPECT_NEAR(std::atan2(f.y(), f.x()) * 180 / kPi, theta1_deg[i], 1e-4);
  }
  EXPECT_NEAR(std::fabs(ch[0].a0 - ch[1].a0), 22.029810, 1e-5);  // ground, both pivots on the θ0 line
  // The seed's printed second chain (78.492, 82.345, 32.637) misses: its free link's length changes
  // from point to point by far more than its rounding.
  double lo = 1e9, hi = 0;
  for (int i = 0; i < 3; ++i) {
    const double l =
        (Vector2d(kPts[i][0], kPts[i][1]) - 78.492 * u(th0) - 32.637 * u(rad(kPts[i][2]))).norm();
    lo = std::min(lo, l);
    hi = std::max(hi, l);
  }
  EXPECT_GT(hi - lo, 5.0);
}

TEST(KnotCycleSeed, DefaultsAreThatLinkage) {
  const KnotCycleSpec s = seed001_knot_cycle_spec();
  const auto ch = eliminate();
  const double th0 = rad(275);
  EXPECT_NEAR(s.crank.length_m, ch[0].a1 * 1e-3, 1e-12);
  EXPECT_NEAR(s.rocker.length_m, ch[1].a1 * 1e-3, 1e-12);
  EXPECT_NEAR(s.coupler.length_m, std::fabs(ch[0].a2 - ch[1].a2) * 1e-3, 1e-12);
  EXPECT_NEAR(s.crank_pivot_x_m, ch[0].a0 * 1e-3 * std::cos(th0), 1e-12);
  EXPECT_NEAR(s.rocker_pivot_y_m, ch[1].a0 * 1e-3 * std::sin(th0), 1e-12);
  // Seed's formulas: m = 30 mm² · L · 1.4159 g/cm³, I_G = m(6² + L²)/12.
  const double L = ch[0].a1;
  EXPECT_NEAR(s.crank.mass_kg, 30 * L * 1.4159e-3 * 1e-3, 1e-8);
  EXPECT_NEAR(s.crank.inertia_kg_m2, s.crank.mass_kg * (36 + L * L) * 1e-6 / 12, 1e-12);
  EXPECT_DOUBLE_EQ(s.coupler.mass_kg, 1.641e-3);
  EXPECT_DOUBLE_EQ(s.coupler.inertia_kg_m2, 208.94e-9);
}

// The test's own geometry: the rocker pin B from the circles about A (coupler) and B0 (rocker), on the
// side the spec's branch picks: positive ⇔ sin(θ3 − θ4) > 0 ⇔ (B − A) × (B − B0) < 0.
struct Pose {
  Vector2d a, b, grip, cg_coupler, cg_rocker;
  double th3, th4;
};
Pose pose_of(const KnotCycleSpec& s, double crank) {
  const Vector2d a0(s.crank_pivot_x_m, s.crank_pivot_y_m), b0(s.rocker_pivot_x_m, s.rocker_pivot_y_m);
  const Vector2d a = a0 + s.crank.length_m * u(crank);
  const Vector2d d = b0 - a;
  const double L = d.norm(), r0 = s.coupler.length_m, r1 = s.rocker.length_m;
  const double x = (L * L + r0 * r0 - r1 * r1) / (2 * L);
  const double h = std::sqrt(std::max(0.0, r0 * r0 - x * x));
  const Vector2d e = d / L, n(-e.y(), e.x());
  Pose p{};
  for (double side : {1.0, -1.0}) {
    const Vector2d b = a + x * e + side * h * n;
    const Vector2d ab = b - a, bb = b - b0;
    const double cross = ab.x() * bb.y() - ab.y() * bb.x();
    if ((cross < 0) == (s.branch == Branch::kPositive)) p.b = b;
  }
  p.a = a;
  const Vector2d ex = (p.b - a) / r0, ey(-ex.y(), ex.x());
  p.grip = a + s.gripper_along_m * ex + s.gripper_normal_m * ey;
  p.cg_coupler = a + s.coupler.cg_m * ex;
  p.cg_rocker = b0 + s.rocker.cg_m * (p.b - b0) / r1;
  p.th3 = std::atan2(ex.y(), ex.x());
  p.th4 = std::atan2(p.b.y() - b0.y(), p.b.x() - b0.x());
  return p;
}

TEST(KnotCycle, DefaultBuildsAndPassesThePoints) {
  const KnotCycleSpec s = seed001_knot_cycle_spec();
  const KnotCycle kc = KnotCycle::build(s);
  const auto& r = kc.report();
  const std::array<double, 3> theta1_deg{-174.1791, 63.4044, 33.7328};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(std::remainder(r.crank_angles_rad[static_cast<std::size_t>(i)] * 180 / kPi -
                                   theta1_deg[static_cast<std::size_t>(i)],
                               360.0),
                0.0, 1e-4);
    const Pose p = pose_of(s, r.crank_angles_rad[static_cast<std::size_t>(i)]);
    EXPECT_NEAR(p.grip.x(), s.points[static_cast<std::size_t>(i)].x_m, 1e-9);
    EXPECT_NEAR(p.grip.y(), s.points[static_cast<std::size_t>(i)].y_m, 1e-9);
    // The coupler line along the gripper angle (the gripper lies beyond the crank joint: +π).
    EXPECT_NEAR(std::remainder(p.th3 - s.points[static_cast<std::size_t>(i)].gripper_rad - kPi, 2 * kPi), 0.0,
                1e-9);
  }
  EXPECT_EQ(r.grashof, loom::motion::GrashofClass::kTripleRocker);
  EXPECT_FALSE(r.full_turn);
  EXPECT_EQ(kc.end_offset_rad(), 0.0);
  EXPECT_NEAR(r.stroke_rad * 180 / kPi, 33.7328 - (360 - 174.1791), 1e-3);  // turning clockwise, 152.1°
  // Transmission angle at TAKE by the law of cosines on (A, B, B0): 38.18°, the least in the stroke.
  const Pose take = pose_of(s, r.crank_angles_rad[0]);
  const Vector2d b0(s.rocker_pivot_x_m, s.rocker_pivot_y_m);
  const double mu = std::acos((take.a - take.b).normalized().dot((b0 - take.b).normalized()));
  EXPECT_NEAR(std::min(mu, kPi - mu) * 180 / kPi, 38.18, 0.01);
  EXPECT_NEAR(r.min_transmission_rad, std::min(mu, kPi - mu), 1e-6);
  // The rest pose and the end.
  EXPECT_NEAR(kc.take_angle_rad(), r.crank_angles_rad[0], 0.0);
  EXPECT_NEAR(kc.sample(0).angle_rad, 0.0, 1e-12);
  EXPECT_NEAR(kc.sample(kc.duration_s()).angle_rad, 0.0, 1e-12);
  EXPECT_NEAR(kc.sample(kc.cutter().begin_s).angle_rad, r.stroke_rad, 1e-7);  // the table's error
}

TEST(KnotCycle, RatesMatchFiniteDifferencesOfTheAngle) {
  const KnotCycle kc = KnotCycle::build(seed001_knot_cycle_spec());
  const double T = kc.duration_s(), h = 1e-6;
  double worst_v = 0, worst_a = 0, peak_v = 0, peak_a = 0;
  int checked = 0;
  for (int k = 1; k < 9973; ++k) {
    const double t = T * k / 9973.0;
    // The acceleration jumps where a move starts, switches from driving to braking, and ends.
    bool near_jump = false;
    for (const auto& seg : kc.report().segments) {
      for (double edge : {seg.begin_s, seg.switch_s, seg.brake_s, seg.end_s})
        near_jump |= std::fabs(t - edge) < 2 * h;
    }
    const auto m = kc.sample(t - h), c = kc.sample(t), p = kc.sample(t + h);
    const double a_fd = (p.velocity_rad_s - m.velocity_rad_s) / (2 * h);
    if (near_jump) {
      // Straddling the switch: the difference averages the two sides; it must lie between them.
      const double lo = std::min({m.accel_rad_s2, c.accel_rad_s2, p.accel_rad_s2}),
                   hi = std::max({m.accel_rad_s2, c.accel_rad_s2, p.accel_rad_s2});
      EXPECT_GE(a_fd, lo - 1e-6 * std::fabs(lo)) << t;
      EXPECT_LE(a_fd, hi + 1e-6 * std::fabs(hi)) << t;
      continue;
    }
    worst_v = std::max(worst_v, std::fabs((p.angle_rad - m.angle_rad) / (2 * h) - c.velocity_rad_s));
    worst_a = std::max(worst_a, std::fabs(a_fd - c.accel_rad_s2));
    peak_v = std::max(peak_v, std::fabs(c.velocity_rad_s));
    peak_a = std::max(peak_a, std::fabs(c.accel_rad_s2));
    ++checked;
  }
  EXPECT_GT(checked, 9850);
  EXPECT_GT(peak_v, 1.0);
  EXPECT_LT(worst_v, 1e-6 * peak_v);
  EXPECT_LT(worst_a, 1e-4 * peak_a);
  EXPECT_LT(peak_v, kc.spec().no_load_speed_rad_s);
}

// The produced profile against the drive's envelope, from nothing but finite differences of the angle it
// commands: at every sample the torque the linkage needs (the model's J α + ½J'ω² + dV/dθ, with ω and
// α from central differences) lies within the torque–speed line.
TEST(KnotCycle, NoSampleExceedsTheTorqueSpeedLine) {
  const KnotCycleSpec s = seed001_knot_cycle_spec();
  const KnotCycle kc = KnotCycle::build(s);
  const TorqueSpeedLine line{s.no_load_speed_rad_s, s.peak_torque_nm};
  const double T = kc.duration_s(), h = 2e-6;
  double least = 1.0;
  for (int k = 1; k < 49999; ++k) {
    const double t = T * k / 49999.0;
    const double m = kc.sample(t - h).angle_rad, c = kc.sample(t).angle_rad, p = kc.sample(t + h).angle_rad;
    const double w = (p - m) / (2 * h), a = (p - 2 * c + m) / (h * h);
    const double tau = kc.torque_at(kc.take_angle_rad() + c, w, a);
    const double avail = line.available_nm(w, tau < 0 ? -1.0 : 1.0);
    ASSERT_LE(std::fabs(tau), avail * (1 + 1e-6) + 1e-9) << "t = " << t << " w = " << w << " a = " << a;
    least = std::min(least, (avail - std::fabs(tau)) / avail);
  }
  // Time-optimal: the moves ride the envelope (within the planning share and the linkage's variation).
  EXPECT_LT(least, 0.02);
  EXPECT_GE(kc.report().envelope_margin, 0.0);
}

// The bang-bang time of a rigid inertia under the line, integrated independently: drive on the line
// (J dω/dt = τp(1 − ω/ω0)) by RK4 until the braking distance at the peak torque closes the move.
double bang_bang_time(double distance, double inertia, double peak, double no_load) {
  const double b = peak / inertia, dt = 1e-7;
  double th = 0, w = 0, t = 0;
  const auto acc = [&](double ww) { return peak / inertia * (1 - ww / no_load); };
  double f = -distance, t_prev = 0, w_prev = 0, f_prev = -distance;
  while (f < 0) {
    t_prev = t;
    w_prev = w;
    f_prev = f;
    const double k1w = acc(w), k1t = w;
    const double k2w = acc(w + 0.5 * dt * k1w), k2t = w + 0.5 * dt * k1w;
    const double k3w = acc(w + 0.5 * dt * k2w), k3t = w + 0.5 * dt * k2w;
    const double k4w = acc(w + dt * k3w), k4t = w + dt * k3w;
    th += dt * (k1t + 2 * k2t + 2 * k3t + k4t) / 6;
    w += dt * (k1w + 2 * k2w + 2 * k3w + k4w) / 6;
    t += dt;
    f = th + w * w / (2 * b) - distance;
  }
  const double u = -f_prev / (f - f_prev);  // the switch between the last two steps, linearly
  return t_prev + u * dt + (w_prev + u * (w - w_prev)) / b;
}

TEST(KnotCycle, MovesTakeTheBangBangTimeOfARigidInertia) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  for (auto link : {&KnotCycleSpec::crank, &KnotCycleSpec::coupler, &KnotCycleSpec::rocker}) {
    (s.*link).mass_kg = 0;
    (s.*link).inertia_kg_m2 = 0;
  }
  s.gravity_m_s2 = 0;  // the rotor alone: J constant, no load torque
  const KnotCycle kc = KnotCycle::build(s);
  for (std::size_t i : {1u, 2u, 5u}) {
    const auto& seg = kc.report().segments[i];
    const double d = std::fabs(seg.distance_rad);
    // Planned at the share 0.995 of the peak; never faster than the full peak allows.
    const double planned =
        bang_bang_time(d, s.rotor_inertia_kg_m2, 0.995 * s.peak_torque_nm, s.no_load_speed_rad_s);
    const double physics = bang_bang_time(d, s.rotor_inertia_kg_m2, s.peak_torque_nm, s.no_load_speed_rad_s);
    EXPECT_NEAR(seg.end_s - seg.begin_s, planned, 2e-7) << seg.name;
    EXPECT_GE(seg.end_s - seg.begin_s, physics - 2e-7) << seg.name;
    EXPECT_EQ(seg.bound, KnotLimit::kTorqueSpeedLine) << seg.name;
  }
}

TEST(KnotCycle, ASpeedCapCruises) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.max_speed_rad_s = 10.0;
  const KnotCycle kc = KnotCycle::build(s);
  EXPECT_EQ(kc.report().segments[5].bound, KnotLimit::kSpeedCap);
  EXPECT_NEAR(kc.report().segments[5].peak_speed_rad_s, 10.0, 1e-9);
  EXPECT_LE(kc.report().peak_speed_rad_s, 10.0 * (1 + 1e-12));
  EXPECT_GT(kc.duration_s(), KnotCycle::build(seed001_knot_cycle_spec()).duration_s() + 0.1);
}

// τ from the energy balance: E = Σ ½ m|v_cg|² + ½ I ω² (each link, rotor on the crank) + Σ m g y_cg,
// all from positions by central differences in time; τ = (dE/dt)/ω.
double energy(const KnotCycleSpec& s, const KnotCycle& kc, double t, double h) {
  auto state = [&](double tt) { return pose_of(s, kc.take_angle_rad() + kc.exact(tt).angle_rad); };
  const Pose m = state(t - h), p = state(t + h), c = state(t);
  const double w1 = kc.exact(t).velocity_rad_s;
  const double w3 = std::remainder(p.th3 - m.th3, 2 * kPi) / (2 * h),
               w4 = std::remainder(p.th4 - m.th4, 2 * kPi) / (2 * h);
  const Vector2d v2 = (p.cg_coupler - m.cg_coupler) / (2 * h), v3 = (p.cg_rocker - m.cg_rocker) / (2 * h);
  const Vector2d a0(s.crank_pivot_x_m, s.crank_pivot_y_m);
  const Vector2d cg1 = a0 + s.crank.cg_m * (c.a - a0) / s.crank.length_m;
  const double j1 =
      s.rotor_inertia_kg_m2 + s.crank.inertia_kg_m2 + s.crank.mass_kg * s.crank.cg_m * s.crank.cg_m;
  const double ke = 0.5 * j1 * w1 * w1 + 0.5 * s.coupler.mass_kg * v2.squaredNorm() +
                    0.5 * s.coupler.inertia_kg_m2 * w3 * w3 + 0.5 * s.rocker.mass_kg * v3.squaredNorm() +
                    0.5 * s.rocker.inertia_kg_m2 * w4 * w4;
  const double pe = s.gravity_m_s2 * (s.crank.mass_kg * cg1.y() + s.coupler.mass_kg * c.cg_coupler.y() +
                                      s.rocker.mass_kg * c.cg_rocker.y());
  return ke + pe;
}

void expect_torque_within(const KnotCycleSpec& s, const KnotCycle& kc, double* peak_out) {
  const double T = kc.duration_s(), h = 2e-6, H = 2e-5;
  double peak = 0;
  int checked = 0;
  for (int k = 1; k < 8000; ++k) {
    const double t = T * k / 8000.0;
    const double w = kc.exact(t).velocity_rad_s;
    if (std::fabs(w) < 0.3) continue;  // τ = Ė/ω is ill-conditioned near rest
    bool near_piece_edge = false;
    for (const auto& seg : kc.report().segments) {
      for (double edge : {seg.begin_s, seg.switch_s, seg.brake_s, seg.end_s})
        near_piece_edge |= std::fabs(t - edge) < 4 * H;
    }
    if (near_piece_edge) continue;
    const double tau = (energy(s, kc, t + H, h) - energy(s, kc, t - H, h)) / (2 * H) / w;
    const auto e = kc.exact(t);
    const double model = kc.torque_at(kc.take_angle_rad() + e.angle_rad, e.velocity_rad_s, e.accel_rad_s2);
    EXPECT_NEAR(tau, model, 2e-3 * s.peak_torque_nm + 1e-4 * std::fabs(model)) << "t = " << t;
    const TorqueSpeedLine line{s.no_load_speed_rad_s, s.peak_torque_nm};
    EXPECT_LE(std::fabs(tau), line.available_nm(w, tau < 0 ? -1.0 : 1.0) + 2e-3 * s.peak_torque_nm)
        << "t = " << t;
    peak = std::max(peak, std::fabs(tau));
    ++checked;
  }
  EXPECT_GT(checked, 1000);
  if (peak_out) *peak_out = peak;
}

TEST(KnotCycle, TorqueWithinLimitByTheEnergyMethod) {
  const KnotCycleSpec s = seed001_knot_cycle_spec();
  const KnotCycle kc = KnotCycle::build(s);
  double peak = 0;
  expect_torque_within(s, kc, &peak);
  EXPECT_GT(peak, 0.0);
}

TEST(KnotCycle, SlowerWhenTheTorqueShrinks) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  const KnotCycle fast = KnotCycle::build(s);
  s.peak_torque_nm /= 4;
  const KnotCycle slow = KnotCycle::build(s);
  s.peak_torque_nm /= 4;
  const KnotCycle slower = KnotCycle::build(s);
  EXPECT_GT(slow.duration_s(), fast.duration_s() + 1e-3);
  EXPECT_GT(slower.duration_s(), slow.duration_s() + 1e-3);
  EXPECT_EQ(slower.report().segments[1].bound, KnotLimit::kTorqueSpeedLine);
  EXPECT_LE(std::fabs(slower.report().peak_torque_nm), s.peak_torque_nm * 1.0001);
  // Near the peak: the planned move brakes at (almost) the peak torque (not needlessly slow).
  EXPECT_GT(std::fabs(slower.report().peak_torque_nm), s.peak_torque_nm * 0.97);
  expect_torque_within(s, slower, nullptr);
}

TEST(KnotCycleRefuses, RmsTorqueAboveTheContinuous) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  const double rms = KnotCycle::build(s).report().rms_torque_nm;
  EXPECT_GT(rms, 0.0);
  EXPECT_LT(rms, s.continuous_torque_nm);
  s.continuous_torque_nm = 0.9 * rms;
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kOutOfBounds);
}

TEST(KnotCycle, WindowsOrderedAndFromTheGeometry) {
  const KnotCycleSpec s = seed001_knot_cycle_spec();
  const KnotCycle kc = KnotCycle::build(s);
  const double T = kc.duration_s();
  const auto g = kc.gripper_closed(), c = kc.cutter(), y = kc.yarn_sample(), w = kc.in_warp();
  for (const auto& win : {g, c, y, w}) {
    EXPECT_GE(win.begin_s, 0.0);
    EXPECT_LT(win.begin_s, win.end_s);
    EXPECT_LE(win.end_s, T);
  }
  EXPECT_EQ(g.begin_s, 0.0);
  EXPECT_NEAR(c.begin_s,
              s.grip_s + kc.report().segments[1].end_s - kc.report().segments[1].begin_s +
                  kc.report().segments[2].end_s - kc.report().segments[2].begin_s,
              1e-12);
  EXPECT_NEAR(c.end_s - c.begin_s, s.cut_s, 1e-12);
  EXPECT_EQ(g.end_s, c.end_s);  // released after the cut
  EXPECT_LE(y.begin_s, c.begin_s);
  EXPECT_NEAR(y.end_s, c.end_s + s.release_s, 1e-12);
  EXPECT_GT(w.begin_s, s.grip_s);
  EXPECT_LT(w.begin_s, c.begin_s);
  EXPECT_GT(w.end_s, y.end_s);
  // Outside the window the gripper (test geometry) is out of the warp by the margin's worth.
  for (int k = 0; k <= 2000; ++k) {
    const double t = T * k / 2000.0;
    const double x = pose_of(s, kc.take_angle_rad() + kc.exact(t).angle_rad).grip.x();
    if (!w.contains(t)) {
      EXPECT_LT(x, s.warp_entry_x_m) << t;
    }
    if (x >= s.warp_entry_x_m) {
      EXPECT_TRUE(w.contains(t)) << t;
    }
  }
}

TEST(KnotCycle, SampleIsFiniteForAnyTime) {
  const KnotCycle kc = KnotCycle::build(seed001_knot_cycle_spec());
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (double t : {nan, -nan, inf, -inf, -1.0, -1e-300, 0.0, 1e-300, 1e300, -1e300, kc.duration_s(),
                   2 * kc.duration_s()}) {
    const auto s = kc.sample(t);
    EXPECT_TRUE(std::isfinite(s.angle_rad) && std::isfinite(s.velocity_rad_s) &&
                std::isfinite(s.accel_rad_s2))
        << t;
  }
  EXPECT_EQ(kc.sample(nan).angle_rad, kc.sample(0).angle_rad);
  EXPECT_EQ(kc.sample(inf).angle_rad, kc.sample(kc.duration_s()).angle_rad);
  EXPECT_EQ(kc.sample(-inf).angle_rad, kc.sample(0).angle_rad);
  for (int k = 0; k <= 100000; ++k) {
    const auto s = kc.sample(kc.duration_s() * k / 100000.0);
    ASSERT_TRUE(std::isfinite(s.angle_rad) && std::isfinite(s.velocity_rad_s) &&
                std::isfinite(s.accel_rad_s2))
        << k;
  }
}

TEST(KnotCycleRefuses, BranchDefect) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.branch = Branch::kNegative;
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kWrongBranch);
}

TEST(KnotCycleRefuses, OrderDefect) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  std::swap(s.points[1], s.points[2]);  // TAKE, PULL, WRAP: the crank would reach them out of order
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kOutOfBounds);
  try {
    KnotCycle::build(s);
  } catch (const MotionError& e) {
    EXPECT_NE(std::string(e.what()).find("order defect"), std::string::npos) << e.what();
  }
}

TEST(KnotCycleRefuses, TransmissionBelowTheMinimumInTheStroke) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.min_transmission_rad = rad(40);  // the stroke has 38.2° at TAKE
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kSingular);
}

TEST(KnotCycleRefuses, LinkageMissingAPoint) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.points[2].x_m += 1e-3;
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kNotAssemblable);
  s = seed001_knot_cycle_spec();
  s.points[1].gripper_rad += rad(1);
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kNotAssemblable);
}

TEST(KnotCycleRefuses, TooWeakToHoldAgainstGravity) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.peak_torque_nm = 1e-5;
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kOutOfBounds);
}

TEST(KnotCycleRefuses, WarpEntryOutsideTakeToWrap) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.warp_entry_x_m = 0.026;  // beyond WRAP
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kInvalidInput);
  s.warp_entry_x_m = 0.0;  // TAKE inside
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kInvalidInput);
}

TEST(KnotCycleRefuses, NonFiniteAndNegativeFields) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const KnotCycleSpec base = seed001_knot_cycle_spec();
  std::vector<double KnotCycleSpec::*> any_finite{
      &KnotCycleSpec::theta0_rad,      &KnotCycleSpec::crank_pivot_x_m,  &KnotCycleSpec::rocker_pivot_y_m,
      &KnotCycleSpec::gripper_along_m, &KnotCycleSpec::gripper_normal_m, &KnotCycleSpec::warp_entry_x_m};
  std::vector<double KnotCycleSpec::*> positive{&KnotCycleSpec::no_load_speed_rad_s,
                                                &KnotCycleSpec::peak_torque_nm,
                                                &KnotCycleSpec::continuous_torque_nm};
  std::vector<double KnotCycleSpec::*> non_negative{&KnotCycleSpec::rotor_inertia_kg_m2,
                                                    &KnotCycleSpec::max_speed_rad_s,
                                                    &KnotCycleSpec::grip_s,
                                                    &KnotCycleSpec::cut_s,
                                                    &KnotCycleSpec::release_s,
                                                    &KnotCycleSpec::gravity_m_s2,
                                                    &KnotCycleSpec::min_transmission_rad};
  for (auto f : any_finite) {
    for (double v : {nan, inf, -inf}) {
      KnotCycleSpec s = base;
      s.*f = v;
      EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kInvalidInput);
    }
  }
  for (auto f : positive) {
    for (double v : {nan, inf, -inf, 0.0, -1.0}) {
      KnotCycleSpec s = base;
      s.*f = v;
      EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kInvalidInput);
    }
  }
  for (auto f : non_negative) {
    for (double v : {nan, inf, -1.0}) {
      KnotCycleSpec s = base;
      s.*f = v;
      EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kInvalidInput);
    }
  }
  for (auto link : {&KnotCycleSpec::crank, &KnotCycleSpec::coupler, &KnotCycleSpec::rocker}) {
    for (auto f : {&loom::motion::KnotLinkSpec::length_m, &loom::motion::KnotLinkSpec::mass_kg,
                   &loom::motion::KnotLinkSpec::inertia_kg_m2}) {
      for (double v : {nan, inf, -1.0}) {
        KnotCycleSpec s = base;
        (s.*link).*f = v;
        EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kInvalidInput);
      }
    }
  }
  KnotCycleSpec s = base;
  s.points[1].y_m = nan;
  EXPECT_EQ(code_of([&] { KnotCycle::build(s); }), ErrorCode::kInvalidInput);
}

// A crank-rocker head built from its own geometry: the crank turns on through the turn to return.
TEST(KnotCycle, CrankRockerTurnsOn) {
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.crank_pivot_x_m = 0;
  s.crank_pivot_y_m = 0;
  s.rocker_pivot_x_m = 0.05;
  s.rocker_pivot_y_m = 0;
  s.crank.length_m = 0.015;
  s.crank.cg_m = 0.0075;
  s.coupler.length_m = 0.045;
  s.coupler.cg_m = 0.02;
  s.rocker.length_m = 0.04;
  s.rocker.cg_m = 0.02;
  s.gripper_along_m = 0.02;
  s.gripper_normal_m = 0.015;
  s.branch = Branch::kPositive;
  const std::array<double, 3> crank{rad(200), rad(280), rad(350)};
  for (std::size_t i = 0; i < 3; ++i) {
    const Pose p = pose_of(s, crank[i]);
    s.points[i] = {p.grip.x(), p.grip.y(), p.th3};
  }
  ASSERT_LT(s.points[0].x_m, s.points[1].x_m);
  s.warp_entry_x_m = 0.5 * (s.points[0].x_m + s.points[1].x_m);
  s.min_transmission_rad = rad(10);
  const KnotCycle kc = KnotCycle::build(s);
  EXPECT_TRUE(kc.report().full_turn);
  EXPECT_NEAR(kc.end_offset_rad(), 2 * kPi, 1e-12);
  EXPECT_NEAR(kc.report().stroke_rad, rad(150), 1e-9);
  EXPECT_NEAR(kc.sample(kc.duration_s()).angle_rad, 2 * kPi, 1e-9);
  EXPECT_NEAR(kc.report().segments[5].distance_rad, rad(210), 1e-9);
  expect_torque_within(s, kc, nullptr);
}

}  // namespace

// Each refusal says which fact of the spec to change (KnotCycleError::field), so loom-synth blames its
// option without reading the message; the field agrees with the fact the message names.
TEST(KnotCycleRefuses, SaysWhichFactToChange) {
  using loom::motion::KnotCycleError;
  using loom::motion::KnotCycleField;
  const auto refusal = [](const KnotCycleSpec& s) -> std::pair<KnotCycleField, std::string> {
    try {
      KnotCycle::build(s);
    } catch (const KnotCycleError& e) {
      return {e.field(), e.what()};
    }
    ADD_FAILURE() << "no KnotCycleError";
    return {KnotCycleField::kLinkage, ""};
  };
  const auto expect = [&](const KnotCycleSpec& s, KnotCycleField field, const char* names) {
    const auto [f, why] = refusal(s);
    EXPECT_EQ(f, field) << why;
    EXPECT_NE(why.find(names), std::string::npos) << why;
  };
  KnotCycleSpec s = seed001_knot_cycle_spec();
  s.peak_torque_nm = 1e-5;  // cannot hold the links against gravity
  expect(s, KnotCycleField::kMaxTorque, "peak_torque_nm");
  s.peak_torque_nm = -1.0;
  expect(s, KnotCycleField::kMaxTorque, "peak_torque_nm");
  s = seed001_knot_cycle_spec();
  s.continuous_torque_nm = 1e-3;  // the cycle's rms torque is far above it
  expect(s, KnotCycleField::kMaxTorque, "continuous_torque_nm");
  s = seed001_knot_cycle_spec();
  s.warp_entry_x_m = 0.026;  // beyond WRAP
  expect(s, KnotCycleField::kWarpEntry, "warp_entry_x_m");
  s.warp_entry_x_m = std::numeric_limits<double>::quiet_NaN();
  expect(s, KnotCycleField::kWarpEntry, "warp_entry_x_m");
  s = seed001_knot_cycle_spec();
  s.min_transmission_rad = rad(40);  // the stroke has 38.2° at TAKE
  expect(s, KnotCycleField::kMinTransmission, "min_transmission_rad");
  s.min_transmission_rad = rad(95);
  expect(s, KnotCycleField::kMinTransmission, "min_transmission_rad");
  s = seed001_knot_cycle_spec();
  s.points[1].gripper_rad += rad(1);  // the linkage misses WRAP's gripper angle
  expect(s, KnotCycleField::kLinkage, "knot cycle");
  s = seed001_knot_cycle_spec();
  s.crank.length_m = 0.0;
  expect(s, KnotCycleField::kLinkage, "crank.length_m");
}
