// What the synthesis costs: closed-form designs (Söylemez, Khare–Dave for one β) against the
// numerical optimum over β and the three-point λ method with its Newton polish. Configure-time
// code, so the point is the order of magnitude, not a budget.
#include <benchmark/benchmark.h>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"
#include "loom/motion/design/three_point.hpp"
#include "loom/motion/slider_crank.hpp"

namespace {

using loom::motion::rad;

void BM_SoylemezOptimum(benchmark::State& state) {
  double phi = rad(169.0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(loom::motion::soylemez_slider_crank(12.0, phi));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_SoylemezOptimum);

void BM_SliderDeadCentres(benchmark::State& state) {
  const auto d = loom::motion::soylemez_slider_crank(12.0, rad(169.0));
  for (auto _ : state) benchmark::DoNotOptimize(loom::motion::slider_dead_centres(d.mechanism));
}
BENCHMARK(BM_SliderDeadCentres);

void BM_SliderState(benchmark::State& state) {
  const auto d = loom::motion::soylemez_slider_crank(12.0, rad(169.0));
  double th = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(loom::motion::slider_state(d.mechanism, th, 15.5, 0.0));
    th += 1e-3;
  }
}
BENCHMARK(BM_SliderState);

void BM_KhareDaveOneBeta(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(loom::motion::khare_dave_crank_rocker(rad(30.0), rad(160.0), rad(55.0)));
  }
}
BENCHMARK(BM_KhareDaveOneBeta);

void BM_KhareDaveBestBeta(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(loom::motion::khare_dave_best_beta(rad(30.0), rad(160.0)));
  }
}
BENCHMARK(BM_KhareDaveBestBeta);

void BM_ThreePoint(benchmark::State& state) {
  const std::array<loom::motion::PrecisionPoint, 3> pts = {loom::motion::PrecisionPoint{0, 0, rad(10)},
                                                           loom::motion::PrecisionPoint{25, 15, rad(3)},
                                                           loom::motion::PrecisionPoint{30, 1, rad(-25)}};
  for (auto _ : state) benchmark::DoNotOptimize(loom::motion::three_point_synthesis(pts, rad(275)));
}
BENCHMARK(BM_ThreePoint);

}  // namespace

BENCHMARK_MAIN();
