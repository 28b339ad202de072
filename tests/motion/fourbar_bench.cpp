// What accuracy costs for the four-bar (issue 6): closed-form positions versus Newton on the loop
// closure at several tolerances, warm-started along a sweep and from a rough guess, on the thesis'
// beat-up linkage and on a crank-rocker one part in a million from its change point (where Newton's
// Jacobian nearly vanishes). Errors are against a long-double Newton polish of the exact loop.
// Run with --markdown for the README table (tools/kinreport/accuracy_report.sh).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bench_sweep.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/fourbar.hpp"
#include "markdown_reporter.hpp"

namespace {

using loom::motion::Branch;
using loom::motion::FourBar;
using loom::motion::FourBarPose;
using loom::motion::NewtonOptions;

constexpr int kSamples = 3600;
constexpr Branch kBranch = Branch::kPositive;

const FourBar kBeatUp{.ground = 0.213, .crank = 0.058, .coupler = 0.189, .rocker = 0.232};
// d = 1, a = 0.4, b = 1.2, c = 0.6 + 1e-6: μ_min ≈ 0.074° at θ2 = 0.
const FourBar kNearChangePoint{.ground = 1.0, .crank = 0.4, .coupler = 1.2, .rocker = 0.6 + 1e-6};

const FourBar& linkage(int which) {
  return which == 0 ? kBeatUp : kNearChangePoint;
}

std::vector<double> cranks() {
  return loom::test::sweep_angles(kSamples);
}

struct Angles {
  double theta3, theta4;
};

// Independent reference: Newton on the loop closure in long double (64-bit mantissa), started from
// the closed form; three quadratic steps take a double-accurate start to ~1e-19.
Angles reference(const FourBar& m, double theta2, const FourBarPose& start) {
  const long double a = m.crank, b = m.coupler, c = m.rocker, d = m.ground, t2 = theta2;
  long double t3 = start.theta3, t4 = start.theta4;
  for (int i = 0; i < 3; ++i) {
    const long double f1 = a * std::cos(t2) + b * std::cos(t3) - d - c * std::cos(t4);
    const long double f2 = a * std::sin(t2) + b * std::sin(t3) - c * std::sin(t4);
    const long double j11 = -b * std::sin(t3), j12 = c * std::sin(t4);
    const long double j21 = b * std::cos(t3), j22 = -c * std::cos(t4);
    const long double det = j11 * j22 - j12 * j21;
    t3 -= (f1 * j22 - j12 * f2) / det;
    t4 -= (j11 * f2 - f1 * j21) / det;
  }
  return {static_cast<double>(t3), static_cast<double>(t4)};
}

double angle_error(const FourBarPose& p, const Angles& ref) {
  return std::max(std::abs(loom::motion::wrap_pi(p.theta3 - ref.theta3)),
                  std::abs(loom::motion::wrap_pi(p.theta4 - ref.theta4)));
}

std::vector<Angles> references(const FourBar& m) {
  std::vector<Angles> r;
  for (double t : cranks()) r.push_back(reference(m, t, solve(m, t, kBranch)));
  return r;
}

// Closed-form position and coefficients (the RT profile builder's call).
void BM_ClosedForm(benchmark::State& state) {
  const FourBar& m = linkage(static_cast<int>(state.range(0)));
  const auto c = cranks();
  const auto ref = references(m);
  double err = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k)
    err = std::max(err, angle_error(solve(m, c[k], kBranch), ref[k]));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(solve(m, c[i], kBranch));
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["max_err_rad"] = err;
}
BENCHMARK(BM_ClosedForm)->ArgName("near_change_point")->Arg(0)->Arg(1);

// Closed-form position only (no coefficients).
void BM_ClosedFormPositionOnly(benchmark::State& state) {
  const FourBar& m = linkage(static_cast<int>(state.range(0)));
  const auto c = cranks();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(solve_position(m, c[i], kBranch));
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ClosedFormPositionOnly)->ArgName("near_change_point")->Arg(0)->Arg(1);

// Newton along the sweep, each solve seeded by the previous sample's angles (Δθ2 = 0.1°).
void BM_NewtonWarm(benchmark::State& state) {
  const FourBar& m = linkage(static_cast<int>(state.range(0)));
  const NewtonOptions opt{std::pow(10.0, -static_cast<double>(state.range(1))), 50};
  const auto c = cranks();
  const auto ref = references(m);
  FourBarPose prev = solve(m, c.back(), kBranch);
  double err = 0.0, iters = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {  // untimed pass: accuracy and steps
    const auto n = solve_newton(m, c[k], kBranch, prev.theta3, prev.theta4, opt);
    err = std::max(err, angle_error(n.pose, ref[k]));
    iters += n.iterations;
    prev = n.pose;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const auto n = solve_newton(m, c[i], kBranch, prev.theta3, prev.theta4, opt);
    benchmark::DoNotOptimize(n);
    prev = n.pose;
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["tol"] = opt.tolerance;
  state.counters["mean_iters"] = iters / kSamples;
  state.counters["max_err_rad"] = err;
}
BENCHMARK(BM_NewtonWarm)->ArgNames({"near_change_point", "tol_exp"})->ArgsProduct({{0, 1}, {4, 8, 12, 14}});

// Newton from a rough guess: both unknowns 0.1 rad off the answer (a drawing read by eye).
void BM_NewtonRough(benchmark::State& state) {
  const FourBar& m = linkage(0);
  const NewtonOptions opt{std::pow(10.0, -static_cast<double>(state.range(0))), 50};
  const auto c = cranks();
  const auto ref = references(m);
  std::vector<Angles> guess;
  double err = 0.0, iters = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    guess.push_back({ref[k].theta3 + 0.1, ref[k].theta4 + 0.1});
    const auto n = solve_newton(m, c[k], kBranch, guess[k].theta3, guess[k].theta4, opt);
    err = std::max(err, angle_error(n.pose, ref[k]));
    iters += n.iterations;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(solve_newton(m, c[i], kBranch, guess[i].theta3, guess[i].theta4, opt));
    i = (i + 1) % c.size();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["tol"] = opt.tolerance;
  state.counters["mean_iters"] = iters / kSamples;
  state.counters["max_err_rad"] = err;
}
BENCHMARK(BM_NewtonRough)->ArgName("tol_exp")->Arg(4)->Arg(8)->Arg(12)->Arg(14);

}  // namespace

int main(int argc, char** argv) {
  return loom::kinreport::run_benchmarks(argc, argv, "Four-bar position: closed form vs Newton");
}
