// What a control tick costs, and what profile accuracy costs: the full cycle (sim HAL read, sequencer,
// write) for the ideal scene and with servo lag named, and the rocker-table lookup against the exact
// linkage solve, with the table's worst error reported as a counter next to its time.
#include <benchmark/benchmark.h>

#include <cmath>

#include "loom/firmware/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/motion/phase_table.hpp"

using namespace loom;

namespace {

void run_ticks(benchmark::State& state, const firmware::Scene& scene) {
  firmware::LoomConfig cfg = firmware::default_loom_config();
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = 1'000'000;
  firmware::Machine m(cfg, scene, opt, {});
  m.sequencer().request_start();
  hal::Tick t = 0;
  for (auto _ : state) m.loop().cycle(t++);
  state.counters["rows"] = m.sequencer().counters().rows;
}

void BM_TickIdeal(benchmark::State& state) { run_ticks(state, firmware::default_scene()); }

void BM_TickServoLag(benchmark::State& state) {
  firmware::Scene s = firmware::default_scene();
  s.spec.effects = {"servo_lag"};
  s.spec.servo_lag = sim_hal::ServoLag{0.004};
  run_ticks(state, s);
}

void BM_RockerExactSolve(benchmark::State& state) {
  const motion::BeatUp b(motion::default_beatup_geometry());
  double p = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(b.at(p).rocker_angle);
    p += 0.001;
  }
}

void BM_RockerTable(benchmark::State& state) {
  const motion::BeatUp b(motion::default_beatup_geometry());
  const motion::PhaseTable table(static_cast<std::size_t>(state.range(0)), [&](double p) {
    const motion::BeaterState s = b.at(p);
    return motion::PhaseTable::Exact{s.rocker_angle, s.d1};
  });
  double err = 0.0;
  for (int i = 0; i < 20011; ++i) {
    const double p = motion::kTwoPi * i / 20011.0;
    err = std::max(err, std::abs(table.at(p).value - b.at(p).rocker_angle));
  }
  double p = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(table.at(p).value);
    p += 0.001;
  }
  state.counters["max_err_rad"] = err;
  state.counters["bytes"] = static_cast<double>(table.bytes());
}

}  // namespace

BENCHMARK(BM_TickIdeal);
BENCHMARK(BM_TickServoLag);
BENCHMARK(BM_RockerExactSolve);
BENCHMARK(BM_RockerTable)->RangeMultiplier(4)->Range(64, 65536);
BENCHMARK_MAIN();
