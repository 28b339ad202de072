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

// One benchmark per effect, each named alone on top of ideal tracking, and all of them together: the
// cost table of "simulate only what the scene names". BM_Tick/ideal is the floor every unnamed effect
// must match.
firmware::Scene scene_with(const std::vector<std::string>& effects) {
  firmware::Scene s;
  s.spec.name = "bench";
  s.spec.effects = effects;
  return s;  // parameter blocks default when an effect is named without one
}

void BM_Tick(benchmark::State& state, std::vector<std::string> effects) { run_ticks(state, scene_with(effects)); }

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

BENCHMARK_CAPTURE(BM_Tick, ideal, std::vector<std::string>{"ideal"});
BENCHMARK_CAPTURE(BM_Tick, servo_lag, std::vector<std::string>{"servo_lag"});
BENCHMARK_CAPTURE(BM_Tick, pneumatics, std::vector<std::string>{"ideal", "pneumatics"});
BENCHMARK_CAPTURE(BM_Tick, shuttle_slip, std::vector<std::string>{"ideal", "shuttle_slip"});
BENCHMARK_CAPTURE(BM_Tick, sensor_noise, std::vector<std::string>{"ideal", "sensor_noise"});
BENCHMARK_CAPTURE(BM_Tick, beat_contact, std::vector<std::string>{"ideal", "beat_contact"});
BENCHMARK_CAPTURE(BM_Tick, inertia, std::vector<std::string>{"inertia"});
BENCHMARK_CAPTURE(BM_Tick, inertia_friction, std::vector<std::string>{"inertia", "joint_friction"});
BENCHMARK_CAPTURE(BM_Tick, all, std::vector<std::string>{"servo_lag", "pneumatics", "shuttle_slip", "sensor_noise",
                                                         "beat_contact", "inertia", "joint_friction"});
BENCHMARK(BM_RockerExactSolve);
BENCHMARK(BM_RockerTable)->RangeMultiplier(4)->Range(64, 65536);
BENCHMARK_MAIN();
