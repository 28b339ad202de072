// What accuracy costs for the batten linkage (004 eqns 7): closed-form positions versus Newton at
// several tolerances, warm-started along a sweep (continuation) and from a rough guess. Each Newton
// case reports its mean iterations and its largest angle error against the closed form.
// Run with --markdown for the README table (tools/kinreport/accuracy_report.sh).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bench_sweep.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/batten.hpp"
#include "markdown_reporter.hpp"

namespace {

using loom::motion::BattenDrive;
using loom::motion::BattenLinkage;
using loom::motion::BattenPose;
using loom::motion::NewtonOptions;

constexpr int kSamples = 3600;

const BattenLinkage& linkage() {
  static const BattenLinkage l(loom::motion::batten_004_dims());
  return l;
}

std::vector<double> cranks() {
  return loom::test::sweep_angles(kSamples);
}

double max_error(const BattenPose& a, const BattenPose& b) {
  return (a.vec() - b.vec())
      .unaryExpr([](double v) { return std::abs(loom::motion::wrap_pi(v)); })
      .maxCoeff();
}

void BM_ClosedForm(benchmark::State& state) {
  const auto c = cranks();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(linkage().solve(c[i]));
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ClosedForm);

// Newton along the sweep, each solve seeded by the previous sample's pose (Δφ2 = 0.1°).
void BM_NewtonWarm(benchmark::State& state) {
  const NewtonOptions opt{std::pow(10.0, -static_cast<double>(state.range(0))), 50};
  const auto c = cranks();
  // Untimed pass: accuracy and iteration count against the closed form.
  BattenPose prev = linkage().solve(c.back());
  double err = 0.0, iters = 0.0;
  for (double crank : c) {
    const auto n = linkage().solve_newton(crank, prev, opt);
    err = std::max(err, max_error(n.pose, linkage().solve(crank)));
    iters += n.iterations;
    prev = n.pose;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const auto n = linkage().solve_newton(c[i], prev, opt);
    benchmark::DoNotOptimize(n);
    prev = n.pose;
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["tol"] = opt.tolerance;
  state.counters["mean_iters"] = iters / kSamples;
  state.counters["max_err_rad"] = err;
}
BENCHMARK(BM_NewtonWarm)->Arg(4)->Arg(8)->Arg(12)->Arg(14);

// Newton from a rough guess: every unknown 0.1 rad off (an assembly drawing read by eye).
void BM_NewtonRough(benchmark::State& state) {
  const NewtonOptions opt{std::pow(10.0, -static_cast<double>(state.range(0))), 50};
  const auto c = cranks();
  std::vector<BattenPose> guess(c.size());
  double err = 0.0, iters = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    BattenPose g = linkage().solve(c[k]);
    g.gamma2_rad += 0.1;
    g.gamma3_rad += 0.1;
    g.gamma4_rad += 0.1;
    g.psi_rad += 0.1;
    guess[k] = g;
    const auto n = linkage().solve_newton(c[k], g, opt);
    err = std::max(err, max_error(n.pose, linkage().solve(c[k])));
    iters += n.iterations;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(linkage().solve_newton(c[i], guess[i], opt));
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["tol"] = opt.tolerance;
  state.counters["mean_iters"] = iters / kSamples;
  state.counters["max_err_rad"] = err;
}
BENCHMARK(BM_NewtonRough)->Arg(4)->Arg(8)->Arg(12)->Arg(14);

// Exact ψ', ψ'' on top of a pose: two 2×2 Cramer solves.
void BM_Rates(benchmark::State& state) {
  const auto c = cranks();
  std::vector<BattenPose> poses;
  for (double crank : c) poses.push_back(linkage().solve(crank));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(linkage().rates(c[i], poses[i], 1.0, 0.0));
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Rates);

// One full drive sample: gear law, closed-form pose and rates.
void BM_DriveSample(benchmark::State& state) {
  const BattenDrive d(loom::motion::EllipticGearPair(loom::motion::kBatten004GearA_m, 0.2, 2), linkage(),
                      1.0);
  const auto c = cranks();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(d.evaluate(c[i], 1.0));
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DriveSample);

}  // namespace

int main(int argc, char** argv) {
  return loom::kinreport::run_benchmarks(
      argc, argv, "Batten linkage (004 eqns 7): closed form vs Newton (errors against the closed form)");
}
