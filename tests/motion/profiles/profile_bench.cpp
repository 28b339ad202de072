// What profile lookups and builds cost (Google Benchmark; the report tool runs the full grid):
// a rocker-table lookup per order, precision and size, the beater through the crank law, the exact
// linkage solve they replace, and a whole ProfileSet build for each crank law.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "loom/motion/profile_set.hpp"

using namespace loom::motion;

namespace {

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ull;

template <Interp I, Precision P>
void BM_RockerLookup(benchmark::State& state) {
  const BeatUp b(default_beatup_geometry());
  const PhaseTable t({.size = static_cast<std::size_t>(state.range(0)), .interp = I, .precision = P},
                     [&](double p) {
                       const BeaterState s = b.at(p);
                       return PhaseExact{s.rocker_angle, s.d1, s.d2};
                     });
  std::uint64_t x = 0;
  for (auto _ : state) {
    x += kGolden;
    benchmark::DoNotOptimize(t.at(Phase{0, x}));
  }
  state.counters["bytes"] = static_cast<double>(t.bytes());
}

void BM_RockerExactSolve(benchmark::State& state) {
  const BeatUp b(default_beatup_geometry());
  std::uint64_t x = 0;
  for (auto _ : state) {
    x += kGolden;
    benchmark::DoNotOptimize(b.at(Phase{0, x}.frac_rad()).rocker_angle);
  }
}

void BM_BeaterThroughEllipticLaw(benchmark::State& state) {
  ProfileSpec s;
  s.crank_law.kind = CrankLawKind::kElliptic;
  const ProfileSet p(s);
  std::uint64_t x = 0;
  for (auto _ : state) {
    x += kGolden;
    benchmark::DoNotOptimize(p.rocker_at(Phase{0, x}));
  }
}

void BM_ProfileSetBuild(benchmark::State& state) {
  ProfileSpec s;
  if (state.range(0) == 1) s.crank_law.kind = CrankLawKind::kElliptic;
  s.table_size = static_cast<std::size_t>(state.range(1));
  for (auto _ : state) {
    const ProfileSet p(s);
    benchmark::DoNotOptimize(&p);
  }
  state.SetLabel(state.range(0) == 1 ? "elliptic law" : "constant law");
}

}  // namespace

BENCHMARK(BM_RockerLookup<Interp::kLinear, Precision::kDouble>)->RangeMultiplier(16)->Range(256, 65536);
BENCHMARK(BM_RockerLookup<Interp::kCubic, Precision::kDouble>)->RangeMultiplier(16)->Range(256, 65536);
BENCHMARK(BM_RockerLookup<Interp::kQuintic, Precision::kDouble>)->RangeMultiplier(16)->Range(256, 65536);
BENCHMARK(BM_RockerLookup<Interp::kCubic, Precision::kFloat>)->RangeMultiplier(16)->Range(256, 65536);
BENCHMARK(BM_RockerLookup<Interp::kQuintic, Precision::kFloat>)->RangeMultiplier(16)->Range(256, 65536);
BENCHMARK(BM_RockerExactSolve);
BENCHMARK(BM_BeaterThroughEllipticLaw);
BENCHMARK(BM_ProfileSetBuild)
    ->Args({0, 256})
    ->Args({1, 256})
    ->Args({0, 4096})
    ->Args({1, 4096})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
