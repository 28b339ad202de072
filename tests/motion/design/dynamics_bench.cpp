// Accuracy against time for the dynamics module. Forward dynamics: each integrator at several steps
// runs one second of the free beat-up (gravity on, no torque; bare, and with a geared drive's
// reflected inertia) and reports, next to its time, the energy drift relative to the initial kinetic
// energy and the crank-angle error against RK4 at 1 µs. Balancing: SLSQP at several tolerances
// reports the objective reached and the evaluations it took. Also the price of one inverse-dynamics
// sample and of one tabulated model evaluation (the per-tick cost in a simulator).
#include <benchmark/benchmark.h>

#include <cmath>

#include "loom/motion/design/balancing.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/forward_dynamics.hpp"

using namespace loom::motion;

namespace {

// Benchmark 1.7's DoNotOptimize on a non-const lvalue uses a "+r,m" asm constraint that GCC may
// satisfy with a general register and hand back a clobbered double; a const reference only reads.
void keep(const double& v) {
  benchmark::DoNotOptimize(v);
}

const BeatUpDynamics& beatup() {
  static const BeatUpDynamics d = [] {
    const BeatUpGeometry g = default_beatup_geometry();
    return BeatUpDynamics(g, beatup_masses(g));
  }();
  return d;
}

// The bare linkage (drive inertia 0) and one driven through a gearbox: a servo rotor of 1e-4 kg m²
// behind 10:1 reflects 0.01 kg m² to the crank, which smooths the motion a great deal.
constexpr double kDriveInertia[2] = {0.0, 0.01};

const BeatUpForwardModel& table(int drive) {
  static const BeatUpForwardModel bare(beatup(), 4096, BeatContact{}, 0.0, kDriveInertia[0]);
  static const BeatUpForwardModel geared(beatup(), 4096, BeatContact{}, 0.0, kDriveInertia[1]);
  return drive == 0 ? bare : geared;
}

constexpr CrankState kStart{0.3, 15.5};
constexpr double kSpan = 1.0;  // s

const CrankState& reference_end(int drive) {
  static const auto run = [](int k) {
    CrankState s = kStart;
    const int n = static_cast<int>(kSpan / 1e-6);
    for (int i = 0; i < n; ++i) s = step_rk4(table(k), s, 1e-6, StepTorque::hold(0.0));
    return s;
  };
  static const CrankState end[2] = {run(0), run(1)};
  return end[drive];
}

enum class Method { kRk4, kEuler };

// Args: step in µs, drive (0 bare, 1 geared).
template <Method M>
void BM_ForwardOneSecond(benchmark::State& state) {
  const double dt = static_cast<double>(state.range(0)) * 1e-6;
  const int drive = static_cast<int>(state.range(1));
  const int n = static_cast<int>(std::lround(kSpan / dt));
  const BeatUpForwardModel& f = table(drive);
  const CrankState ref = reference_end(drive);
  CrankState s = kStart;
  for (auto _ : state) {
    s = kStart;
    for (int i = 0; i < n; ++i) {
      if constexpr (M == Method::kRk4) {
        s = step_rk4(f, s, dt, StepTorque::hold(0.0));
      } else {
        s = step_semi_implicit_euler(f, s, dt, 0.0);
      }
    }
    keep(s.theta_rad);
  }
  const double e0 = f.energy_j(kStart) - f.potential_j(kStart.theta_rad);  // initial kinetic energy
  state.counters["dt_us"] = static_cast<double>(state.range(0));
  state.counters["drive_kg_m2"] = kDriveInertia[drive];
  state.counters["energy_drift_rel"] = std::abs(f.energy_j(s) - f.energy_j(kStart)) / e0;
  state.counters["angle_err_rad"] = std::abs(s.theta_rad - ref.theta_rad);
  state.counters["steps"] = n;
}
BENCHMARK(BM_ForwardOneSecond<Method::kRk4>)
    ->ArgsProduct({{2000, 1000, 500, 100, 10}, {0, 1}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ForwardOneSecond<Method::kEuler>)
    ->ArgsProduct({{1000, 100, 10, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

// RK4 through the exact linkage solve (geared drive, 1 ms): what the table saves, and how close it stays.
void BM_ForwardOneSecondExactModel(benchmark::State& state) {
  const BeatUpExactForwardModel exact(beatup(), BeatContact{}, 0.0, kDriveInertia[1]);
  const double dt = 1e-3;
  CrankState s = kStart;
  for (auto _ : state) {
    s = kStart;
    for (int i = 0; i < 1000; ++i) s = step_rk4(exact, s, dt, StepTorque::hold(0.0));
    keep(s.theta_rad);
  }
  state.counters["angle_err_rad"] = std::abs(s.theta_rad - reference_end(1).theta_rad);
  const double e0 = exact.energy_j(kStart);
  state.counters["energy_drift_rel"] =
      std::abs(exact.energy_j(s) - e0) / (e0 - beatup().potential_energy(kStart.theta_rad));
}
BENCHMARK(BM_ForwardOneSecondExactModel)->Unit(benchmark::kMillisecond);

// Table resolution against the exact reduced model: worst relative error of M and build-free lookup cost.
void BM_TableAcceleration(benchmark::State& state) {
  const BeatUpForwardModel f(beatup(), static_cast<std::size_t>(state.range(0)));
  double worst = 0.0;
  for (int i = 0; i < 2003; ++i) {
    const double th = 2.0 * 3.141592653589793 * i / 2003.0;
    const double exact = beatup().reduced(th).inertia_kg_m2;
    worst = std::max(worst, std::abs(f.terms(th).inertia_kg_m2 - exact) / exact);
  }
  CrankState s{0.0, 15.5};
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.acceleration(s, 0.5));
    s.theta_rad += 0.001;
  }
  state.counters["inertia_err_rel"] = worst;
}
BENCHMARK(BM_TableAcceleration)->Arg(256)->Arg(1024)->Arg(4096);

void BM_InverseDynamicsSample(benchmark::State& state) {
  double th = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(beatup().inverse({th, 15.5, 0.0}, BeatContact{80.0}).forces.crank_torque_nm);
    th += 0.01;
  }
}
BENCHMARK(BM_InverseDynamicsSample);

// SLSQP tolerance against the objective reached (counterweights, w1 = w2 = 0.5, 360 samples).
void BM_BalanceTolerance(benchmark::State& state) {
  static const LinkageMotionSamples s = beatup_balancing_samples(beatup(), 15.5, 360);
  BalanceOptions o;
  o.xtol_rel = std::pow(10.0, -static_cast<double>(state.range(0)));
  o.ftol_rel = 0.0;
  BalanceResult r;
  for (auto _ : state) {
    r = balance_with_counterweights(s, o);
    keep(r.objective_after);
  }
  state.counters["xtol_rel_exp"] = -static_cast<double>(state.range(0));
  state.counters["objective"] = r.objective_after;
  state.counters["evaluations"] = r.evaluations;
  state.counters["force_reduction"] = r.force_reduction();
  state.counters["moment_reduction"] = r.moment_reduction();
  state.counters["converged"] = r.converged ? 1 : 0;
}
BENCHMARK(BM_BalanceTolerance)->DenseRange(2, 12, 2)->Unit(benchmark::kMillisecond);

void BM_BalanceRedistribution(benchmark::State& state) {
  static const LinkageMotionSamples s = beatup_balancing_samples(beatup(), 15.5, 360);
  BalanceOptions o;
  o.xtol_rel = std::pow(10.0, -static_cast<double>(state.range(0)));
  o.ftol_rel = 0.0;
  BalanceResult r;
  for (auto _ : state) {
    r = balance_by_redistribution(s, o);
    keep(r.objective_after);
  }
  state.counters["xtol_rel_exp"] = -static_cast<double>(state.range(0));
  state.counters["objective"] = r.objective_after;
  state.counters["evaluations"] = r.evaluations;
}
BENCHMARK(BM_BalanceRedistribution)->DenseRange(2, 12, 4)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
