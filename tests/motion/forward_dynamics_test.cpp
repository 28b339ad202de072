// Forward dynamics: the table model against the exact reduced model, energy conservation and the
// work of a constant torque, the integrators' orders of accuracy, and the round trip — a motion's
// torque from Newton–Euler inverse dynamics, fed to the forward model, gives the motion back.
#include "loom/motion/forward_dynamics.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "loom/motion/dynamics.hpp"

using namespace loom::motion;

namespace {

BeatUpDynamics thesis_beatup() {
  const BeatUpGeometry g = default_beatup_geometry();
  return BeatUpDynamics(g, beatup_masses(g));
}

template <class Model>
CrankState run_rk4(const Model& m, CrankState s, double dt, int steps, double torque) {
  for (int i = 0; i < steps; ++i) s = step_rk4(m, s, dt, StepTorque::hold(torque));
  return s;
}

}  // namespace

TEST(ForwardDynamics, TableMatchesExactReducedModel) {
  const BeatUpDynamics d = thesis_beatup();
  const BeatUpForwardModel f(d, 4096);
  double worst_m = 0.0, worst_dm = 0.0, worst_g = 0.0;
  for (int i = 0; i < 997; ++i) {
    const double th = kTwoPi * i / 997.0;
    const ReducedTerms e = d.reduced(th), t = f.terms(th);
    worst_m = std::max(worst_m, std::abs(e.inertia_kg_m2 - t.inertia_kg_m2) / e.inertia_kg_m2);
    worst_dm = std::max(worst_dm, std::abs(e.dinertia_kg_m2_rad - t.dinertia_kg_m2_rad));
    worst_g = std::max(worst_g, std::abs(e.gravity_torque_nm - t.gravity_torque_nm));
    EXPECT_NEAR(f.potential_j(th), d.potential_energy(th), 1e-9);
  }
  EXPECT_LT(worst_m, 1e-10);
  EXPECT_LT(worst_dm, 1e-6);
  EXPECT_LT(worst_g, 1e-6);
}

TEST(ForwardDynamics, Rk4ConservesEnergyOfTheFreeLinkage) {
  // No torque, no friction, gravity on: the tabulated model is conservative by construction, so any
  // drift is the integrator's. The free linkage is fast (the beater swings the speed between 12 and
  // 20 rad/s within a turn): RK4 needs 10 µs to hold the energy to 1e-8 of the kinetic energy.
  const BeatUpDynamics d = thesis_beatup();
  const BeatUpForwardModel f(d);
  const CrankState s0{0.3, 12.0};
  const CrankState s1 = run_rk4(f, s0, 1e-5, 100000, 0.0);
  const double ke0 = f.energy_j(s0) - f.potential_j(s0.theta_rad);
  EXPECT_GT(s1.theta_rad - s0.theta_rad, 15.0);  // it really turned, several times
  EXPECT_NEAR(f.energy_j(s1), f.energy_j(s0), 1e-8 * ke0);
}

TEST(ForwardDynamics, ConstantTorqueWorkEqualsEnergyGain) {
  // With a constant motor torque and no losses, ΔE = τ·Δθ exactly.
  const BeatUpDynamics d = thesis_beatup();
  const BeatUpForwardModel f(d);
  const double tau = 0.8;
  const CrankState s0{1.0, 5.0};
  const CrankState s1 = run_rk4(f, s0, 1e-5, 50000, tau);
  const double work = tau * (s1.theta_rad - s0.theta_rad);
  EXPECT_GT(work, 5.0);
  EXPECT_NEAR(f.energy_j(s1) - f.energy_j(s0), work, 1e-7 * work);
}

TEST(ForwardDynamics, FrictionAndClothOnlyTakeEnergy) {
  // Driven through the beat by a constant torque: d(E − τθ)/dt = Q·ω − cω² <= 0 at every step, and
  // per turn the cloth alone takes force × warp depth (to the accuracy a force that switches on
  // inside a step allows).
  const BeatUpDynamics d = thesis_beatup();
  const double tau = 3.0, force = 20.0;
  const BeatUpForwardModel lossy(d, 4096, BeatContact{force}, 0.01);
  CrankState s{0.0, 15.0};
  double w = lossy.energy_j(s) - tau * s.theta_rad;
  for (int i = 0; i < 20000; ++i) {
    s = step_rk4(lossy, s, 5e-5, StepTorque::hold(tau));
    const double now = lossy.energy_j(s) - tau * s.theta_rad;
    ASSERT_LE(now, w + 1e-10) << i;
    ASSERT_GT(s.omega_rad_s, 0.0);
    w = now;
  }
  const BeatUpForwardModel cloth(d, 4096, BeatContact{force}, 0.0);
  CrankState c{0.0, 15.0};
  const double w0 = cloth.energy_j(c) - tau * c.theta_rad;
  while (c.theta_rad < 3.0 * kTwoPi) c = step_rk4(cloth, c, 2e-5, StepTorque::hold(tau));
  const double lost = w0 - (cloth.energy_j(c) - tau * c.theta_rad);
  EXPECT_NEAR(lost, 3.0 * force * d.head().geometry().warp_depth_m, 0.01 * 3.0 * force * 0.05);
}

TEST(ForwardDynamics, IntegratorsConvergeAtTheirOrders) {
  // Reference: RK4 at a tiny step. Halving the step divides RK4's error by ~16, Euler's by ~2. With a
  // drive inertia (motor and gears reflected to the crank) the motion is smooth enough to be in the
  // asymptotic regime at practical steps; the bare linkage needs far smaller ones (benchmark).
  const BeatUpDynamics d = thesis_beatup();
  const BeatUpForwardModel f(d, 4096, BeatContact{}, 0.0, 0.05);
  const CrankState s0{0.2, 14.0};
  const double T = 0.4, tau = 0.5;
  const CrankState ref = run_rk4(f, s0, T / 64000, 64000, tau);
  const auto rk4_err = [&](int n) {
    return std::abs(run_rk4(f, s0, T / n, n, tau).theta_rad - ref.theta_rad);
  };
  const auto euler_err = [&](int n) {
    CrankState s = s0;
    for (int i = 0; i < n; ++i) s = step_semi_implicit_euler(f, s, T / n, tau);
    return std::abs(s.theta_rad - ref.theta_rad);
  };
  EXPECT_NEAR(rk4_err(400) / rk4_err(800), 16.0, 3.0);
  EXPECT_NEAR(euler_err(4000) / euler_err(8000), 2.0, 0.2);
}

TEST(ForwardDynamics, InverseThenForwardRoundTripsTheMotion) {
  // A speed law θ(t) = ω0 t + β sin νt; its torque from the Newton–Euler pin solve (not the reduced
  // model); RK4 through the exact reduced model must come back to the law.
  const BeatUpDynamics d = thesis_beatup();
  const double w0 = 15.5, beta = 0.2, nu = 9.0;
  const auto law = [&](double t) {
    return CrankMotion{w0 * t + beta * std::sin(nu * t), w0 + beta * nu * std::cos(nu * t),
                       -beta * nu * nu * std::sin(nu * t)};
  };
  const auto torque = [&](double t) { return d.inverse(law(t)).forces.crank_torque_nm; };
  const BeatUpExactForwardModel exact(d);
  const BeatUpForwardModel table(d, 8192);
  const double dt = 5e-4;
  const int steps = 1000;  // 0.5 s, more than a turn
  CrankState se{law(0).theta_rad, law(0).omega_rad_s}, st = se;
  for (int i = 0; i < steps; ++i) {
    const double t = i * dt;
    const StepTorque tau{torque(t), torque(t + 0.5 * dt), torque(t + dt)};
    se = step_rk4(exact, se, dt, tau);
    st = step_rk4(table, st, dt, tau);
  }
  const CrankMotion end = law(steps * dt);
  EXPECT_NEAR(se.theta_rad, end.theta_rad, 1e-7);
  EXPECT_NEAR(se.omega_rad_s, end.omega_rad_s, 1e-5);
  EXPECT_NEAR(st.theta_rad, end.theta_rad, 1e-6);
  EXPECT_NEAR(st.omega_rad_s, end.omega_rad_s, 1e-4);
}
