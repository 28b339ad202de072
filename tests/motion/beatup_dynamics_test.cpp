// Beat-up inverse dynamics against independent truths: the Lagrangian reduced model (from kinematic
// coefficients alone), momentum balance of the whole linkage (shaking load = frame reactions),
// finite differences of the beater's path, the work–energy theorem over a partial turn, and the
// thesis' Working Model numbers within a stated tolerance. Hard cases: near toggle, singular, NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "loom/motion/dynamics.hpp"
#include "loom/motion/errors.hpp"

using namespace loom::motion;

namespace {

BeatUpDynamics thesis_beatup() {
  const BeatUpGeometry g = default_beatup_geometry();
  return BeatUpDynamics(g, beatup_masses(g));
}

// Composite Simpson on [a, b] with n (even) panels.
double simpson(const std::function<double(double)>& f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return s * h / 3.0;
}

}  // namespace

TEST(BeatUpDynamics, NewtonEulerTorqueEqualsLagrangianReducedModel) {
  const BeatUpDynamics d = thesis_beatup();
  const BeatContact contact{120.0};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> th(0.0, kTwoPi), w(-25.0, 25.0), al(-300.0, 300.0);
  for (int i = 0; i < 200; ++i) {
    const CrankMotion c{th(rng), w(rng), al(rng)};
    const BeatUpSample s = d.inverse(c, contact);
    const ReducedTerms t = d.reduced(c.theta_rad);
    const double q = d.contact_generalized_force(c, contact);
    const double lagrange = t.inertia_kg_m2 * c.alpha_rad_s2 +
                            0.5 * t.dinertia_kg_m2_rad * c.omega_rad_s * c.omega_rad_s + t.gravity_torque_nm -
                            q;
    EXPECT_NEAR(s.forces.crank_torque_nm, lagrange, 1e-9 * (1.0 + std::abs(lagrange))) << c.theta_rad;
  }
}

TEST(BeatUpDynamics, ReducedTermsAreDerivativesOfInertiaAndPotential) {
  const BeatUpDynamics d = thesis_beatup();
  const double h = 1e-5;
  for (int i = 0; i < 36; ++i) {
    const double th = kTwoPi * i / 36.0 + 0.01;
    const ReducedTerms t = d.reduced(th);
    const double dm = (d.reduced(th + h).inertia_kg_m2 - d.reduced(th - h).inertia_kg_m2) / (2 * h);
    const double dv = (d.potential_energy(th + h) - d.potential_energy(th - h)) / (2 * h);
    EXPECT_NEAR(t.dinertia_kg_m2_rad, dm, 1e-7 * (1.0 + std::abs(dm))) << th;
    EXPECT_NEAR(t.gravity_torque_nm, dv, 1e-7 * (1.0 + std::abs(dv))) << th;
    // Kinetic energy at unit speed is ½M.
    EXPECT_NEAR(d.kinetic_energy({th, 1.0, 0.0}), 0.5 * t.inertia_kg_m2, 1e-15);
  }
}

TEST(BeatUpDynamics, FrameReactionsBalanceTheShakingLoad) {
  // Σ m a_G = F_A0 + F_B0 + Σ m g + F_cloth;  dH/dt about A0 = T + B0×F_B0 + Σ r_G×m g + r_tip×F_cloth.
  const BeatUpDynamics d = thesis_beatup();
  const Eigen::Vector2d g = d.options().gravity_m_s2;
  double total_mass = 0.0;
  for (const PlanarInertia& b : d.bodies()) total_mass += b.mass_kg;
  for (int i = 0; i < 72; ++i) {
    const CrankMotion c{kTwoPi * i / 72.0, 16.0, 40.0};
    const BeatUpSample s = d.inverse(c, BeatContact{90.0});
    const std::array<BodyMotion, 3> mo = d.motion(c);
    const ShakingLoad sh = shaking_load(d.bodies(), mo, Eigen::Vector2d::Zero());
    const Eigen::Vector2d f = s.forces.pin_a0_n + s.forces.pin_b0_n + total_mass * g + s.contact_force_n;
    EXPECT_NEAR((sh.force_n - f).norm(), 0.0, 1e-9 * (1.0 + sh.force_n.norm()));
    double n = s.forces.crank_torque_nm + cross2(mo[2].origin_m, s.forces.pin_b0_n) +
               cross2(s.tip_m, s.contact_force_n);
    for (int k = 0; k < 3; ++k) n += cross2(mo[k].point(d.bodies()[k].centre_m), d.bodies()[k].mass_kg * g);
    EXPECT_NEAR(sh.moment_nm, n, 1e-9 * (1.0 + std::abs(n)));
  }
}

TEST(BeatUpDynamics, TipAccelerationMatchesFiniteDifferencesOfItsPath) {
  // A non-uniform speed law θ(t) = ω0 t + β sin(νt): differentiate the tip position numerically.
  const BeatUpDynamics d = thesis_beatup();
  const double w0 = 15.0, beta = 0.3, nu = 7.0;
  const auto law = [&](double t) {
    return CrankMotion{w0 * t + beta * std::sin(nu * t), w0 + beta * nu * std::cos(nu * t),
                       -beta * nu * nu * std::sin(nu * t)};
  };
  const double h = 1e-4;
  for (int i = 0; i < 50; ++i) {
    const double t = 0.0083 * i;
    const BeatUpSample s = d.inverse(law(t));
    const Eigen::Vector2d p0 = d.inverse(law(t - h)).tip_m, p1 = d.inverse(law(t + h)).tip_m;
    const Eigen::Vector2d v = (p1 - p0) / (2 * h), a = (p1 - 2 * s.tip_m + p0) / (h * h);
    EXPECT_NEAR((s.tip_vel_m_s - v).norm(), 0.0, 1e-6 * (1.0 + v.norm()));
    EXPECT_NEAR((s.tip_acc_m_s2 - a).norm(), 0.0, 1e-4 * (1.0 + a.norm()));
    EXPECT_NEAR(s.beater_force_n, d.masses().beater_kg * s.tip_acc_m_s2.norm(), 1e-12);
  }
}

TEST(BeatUpDynamics, CrankWorkEqualsEnergyChangePlusClothWorkOverAPartialTurn) {
  // Constant crank acceleration from ω0, so kinetic energy changes; through the warp window, so the
  // cloth does work; integrate in θ, split where the cloth force switches on and off.
  const BeatUpDynamics d = thesis_beatup();
  const BeatContact contact{150.0};
  const double w0 = 9.0, alpha = 35.0;
  const double park = d.head().park_crank_angle();
  const WarpWindow& win = d.head().warp();
  const double a = park + win.enter - 0.6, b = park + win.fell + 0.9;
  const auto omega = [&](double th) { return std::sqrt(w0 * w0 + 2.0 * alpha * (th - a)); };
  const auto torque = [&](double th) {
    return d.inverse({th, omega(th), alpha}, contact).forces.crank_torque_nm;
  };
  const auto cloth = [&](double th) {
    const BeatUpSample s = d.inverse({th, omega(th), alpha}, contact);
    return s.contact_force_n.dot(s.tip_vel_m_s) / omega(th);  // F·dr/dθ
  };
  const double eps = 1e-10;  // the contact segment starts a hair inside, where the cloth acts
  const double from[3] = {a, park + win.enter + eps, park + win.fell};
  const double to[3] = {park + win.enter, park + win.fell, b};
  double work = 0.0, cloth_work = 0.0;
  for (int k = 0; k < 3; ++k) {
    work += simpson(torque, from[k], to[k], 4000);
    cloth_work += simpson(cloth, from[k], to[k], 4000);
  }
  const double dke = d.kinetic_energy({b, omega(b), alpha}) - d.kinetic_energy({a, w0, alpha});
  const double dpe = d.potential_energy(b) - d.potential_energy(a);
  EXPECT_LT(cloth_work, -1.0);  // the cloth really took work
  EXPECT_NEAR(work, dke + dpe - cloth_work, 1e-6 * std::abs(work));
}

TEST(BeatUpDynamics, ClothTakesForceTimesWarpDepthPerTurn) {
  // At constant speed over a whole turn ΔKE = ΔPE = 0: the crank's work is what the cloth took,
  // force × the arc the tip advances through the warp = force × warp depth.
  const BeatUpDynamics d = thesis_beatup();
  const BeatContact contact{100.0};
  const double park = d.head().park_crank_angle();
  const WarpWindow& win = d.head().warp();
  const auto torque = [&](double th) { return d.inverse({th, 15.5, 0.0}, contact).forces.crank_torque_nm; };
  // From the previous exit to this one: [exit−2π, enter], [enter, fell] (advancing), [fell, exit].
  // The cloth switches on at `enter`: the contact segment starts a hair inside, so Simpson's end
  // sample sees the force that acts on the segment rather than the one just before it.
  const double eps = 1e-10;
  const double from[3] = {park + win.exit - kTwoPi, park + win.enter + eps, park + win.fell};
  const double to[3] = {park + win.enter, park + win.fell, park + win.exit};
  double work = 0.0;
  for (int k = 0; k < 3; ++k) work += simpson(torque, from[k], to[k], 6000);
  EXPECT_NEAR(work, contact.force_n * d.head().geometry().warp_depth_m, 1e-6 * contact.force_n * 0.05);
}

TEST(BeatUpDynamics, ThesisWorkingModelBeatForcesWithinStatedTolerance) {
  // Thesis §5.2.1 at 15.5 rad/s (printed "m/s"): 87.047 N at the beat, 73.965 N at the bottom (fell)
  // position. Our model: the bottom value within 1 %, the peak within 5 % (it comes out 3.7 % lower:
  // Working Model's own geometry was placed graphically).
  const BeatUpDynamics d = thesis_beatup();
  const BeatForcePeak p = d.peak_beat_force(15.5);
  EXPECT_NEAR(p.fell_force_n, 73.965, 0.01 * 73.965);
  EXPECT_NEAR(p.force_n, 87.047, 0.05 * 87.047);
  EXPECT_LT(p.force_n, 87.047);
  // The beat force is m·|a| with a ∝ ω² at constant speed.
  EXPECT_NEAR(d.peak_beat_force(31.0).force_n, 4.0 * p.force_n, 1e-9 * p.force_n);
}

TEST(BeatUpDynamics, CrankSpeedForTargetForceHitsTheTargetInTheWarp) {
  const BeatUpDynamics d = thesis_beatup();
  for (const double target : {80.0, 90.0, 100.0}) {
    const double w = d.crank_speed_for_beat_force(target);
    double peak = 0.0;
    for (int i = 0; i < 20000; ++i) {
      const BeatUpSample s = d.inverse({kTwoPi * i / 20000.0, w, 0.0});
      if (s.in_warp) peak = std::max(peak, s.beater_force_n);
    }
    EXPECT_LE(peak, target * (1.0 + 1e-9));
    EXPECT_GT(peak, target * (1.0 - 1e-5));  // the dense grid comes close to the refined maximum
  }
  EXPECT_THROW((void)d.crank_speed_for_beat_force(-5.0), MotionError);
}

TEST(BeatUpDynamics, NearToggleForcesGrowButStayFiniteAndFlagged) {
  // a + b = c + d − ε: at θ2 = 0 the coupler and rocker nearly fold (transmission angle → 0).
  BeatUpGeometry g;
  g.bar = FourBar{.ground = 0.2, .crank = 0.05, .coupler = 0.2499, .rocker = 0.1};
  g.beater_arm_m = 0.15;
  g.warp_depth_m = 0.01;
  const BeatUpDynamics d(g, beatup_masses(g));
  const BeatUpSample near = d.inverse({0.0, 10.0, 0.0});
  const BeatUpSample far = d.inverse({kPi, 10.0, 0.0});
  EXPECT_TRUE(near.near_toggle);
  EXPECT_FALSE(far.near_toggle);
  EXPECT_TRUE(near.forces.pin_b_n.allFinite());
  EXPECT_TRUE(std::isfinite(near.forces.crank_torque_nm));
  EXPECT_GT(near.forces.pin_b_n.norm(), 20.0 * far.forces.pin_b_n.norm());
  EXPECT_LT(near.forces.rcond, far.forces.rcond);
}

TEST(BeatUpDynamics, SingularForceSystemIsATypedErrorNotNaN) {
  // A pose with coupler and rocker exactly in line: no pin force at B can hold the rocker's moment.
  const FourBar m{.ground = 0.2, .crank = 0.05, .coupler = 0.25, .rocker = 0.1};
  FourBarPose p;
  p.theta2 = 0.0;
  p.theta3 = 0.0;  // A=(0.05,0) → B=(0.3,0): rocker from B0=(0.2,0) at θ4 = 0, colinear with AB
  p.theta4 = 0.0;
  const BeatUpMasses bm =
      beatup_masses(BeatUpGeometry{m, Branch::kPositive, 0.15, FellSide::kExtended, 0.01});
  const FourBarInertias in{bm.crank, bm.coupler, bm.rocker_with_beater()};
  try {
    (void)four_bar_forces(m, in, p, 10.0, 0.0, {0.0, -9.81});
    FAIL() << "expected kSingular";
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kSingular);
  }
  const BeatUpDynamics d = thesis_beatup();
  try {
    (void)d.inverse({1.0, std::nan(""), 0.0});
    FAIL() << "expected kInvalidInput";
  } catch (const MotionError& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
  }
}
