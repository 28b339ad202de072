// What a control tick costs, and what profile accuracy costs: the full cycle (sim HAL read, sequencer,
// write) for the ideal scene and with servo lag named, and the rocker-table lookup against the exact
// linkage solve, with the table's worst error reported as a counter next to its time.
//
// The *AfterSleep benchmarks ask why a tick costs more in real time than back to back: the same tick
// (default scene, telemetry off) after the core slept a control period, with and without a rehearsal
// (one tick run shortly before, then a spin to the deadline, so the measured tick finds its code and
// data in the caches), and, as the machine's floor, touching N cache lines of one buffer after the
// same sleep. Each reports p50/p99.9/max in ns as counters. Run them at the loop's priority:
//   chrt -f 80 build/bin/loom_bench_tick --benchmark_filter=AfterSleep
// LOOM_BENCH_SLEEP_ITERS sets the samples per benchmark (default 5000, 10 s each at 2 ms).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
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

void BM_Tick(benchmark::State& state, std::vector<std::string> effects) {
  run_ticks(state, scene_with(effects));
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

// ---------------------------------------------------------------------------------------------------
// After a sleep
// ---------------------------------------------------------------------------------------------------
// The loop's own clock: the same clock_nanosleep to absolute deadlines the runner sleeps with.
firmware::MonotonicClock g_clock;
std::int64_t now_ns() {
  return g_clock.now_ns();
}
void sleep_until_ns(std::int64_t deadline) {
  g_clock.sleep_until(deadline);
}

void spin_until_ns(std::int64_t deadline) {
  while (now_ns() < deadline) {
  }
}

constexpr std::int64_t kPeriodNs = 2'000'000;  // the default loom's control period

std::int64_t sleep_iterations() {
  const char* env = std::getenv("LOOM_BENCH_SLEEP_ITERS");
  const long long n = env != nullptr ? std::atoll(env) : 5000;
  return n > 0 ? n : 5000;
}

void report_percentiles(benchmark::State& state, std::vector<std::int64_t>& ns) {
  if (ns.empty()) return;
  std::sort(ns.begin(), ns.end());
  const auto at = [&](double q) {
    return static_cast<double>(
        ns[std::min(ns.size() - 1, static_cast<std::size_t>(q * static_cast<double>(ns.size())))]);
  };
  state.counters["p50_ns"] = at(0.5);
  state.counters["p99.9_ns"] = at(0.999);
  state.counters["max_ns"] = static_cast<double>(ns.back());
}

// The tick after the core slept until its deadline. rehearse_us > 0: a tick runs that many µs before the
// deadline and the core spins until it (the machine then advances two ticks per period: a measurement
// device, not something the loop could do, since a tick moves the machine).
void BM_TickAfterSleep(benchmark::State& state) {
  const std::int64_t rehearse_ns = state.range(0) * 1000;
  firmware::LoomConfig cfg = firmware::default_loom_config();
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = 1'000'000;
  firmware::Machine m(cfg, firmware::default_scene(), opt, {});
  m.sequencer().request_start();
  hal::Tick t = 0;
  for (; t < 2000; ++t) m.loop().cycle(t);  // past bring-up, into weaving
  std::vector<std::int64_t> ns;
  ns.reserve(static_cast<std::size_t>(state.max_iterations));
  std::int64_t deadline = now_ns();
  for (auto _ : state) {
    deadline += kPeriodNs;
    if (rehearse_ns > 0) {
      sleep_until_ns(deadline - rehearse_ns);
      m.loop().cycle(t++);
      spin_until_ns(deadline);
    } else {
      sleep_until_ns(deadline);
    }
    const std::int64_t t0 = now_ns();
    m.loop().cycle(t++);
    const std::int64_t cost = now_ns() - t0;
    state.SetIterationTime(static_cast<double>(cost) * 1e-9);
    ns.push_back(cost);
  }
  report_percentiles(state, ns);
  state.counters["rows"] = m.sequencer().counters().rows;
}

// The machine's floor: reading N cache lines of one 64 KB buffer after the same sleep (N = 0: the two
// clock reads alone).
void BM_CacheLinesAfterSleep(benchmark::State& state) {
  static std::uint8_t buffer[64 * 1024];
  const auto lines = static_cast<std::size_t>(state.range(0));
  std::vector<std::int64_t> ns;
  ns.reserve(static_cast<std::size_t>(state.max_iterations));
  std::int64_t deadline = now_ns();
  unsigned sum = 0;
  for (auto _ : state) {
    deadline += kPeriodNs;
    sleep_until_ns(deadline);
    const std::int64_t t0 = now_ns();
    for (std::size_t i = 0; i < lines; ++i) sum += static_cast<const volatile std::uint8_t*>(buffer)[i * 64];
    const std::int64_t cost = now_ns() - t0;
    state.SetIterationTime(static_cast<double>(cost) * 1e-9);
    ns.push_back(cost);
  }
  benchmark::DoNotOptimize(sum);
  report_percentiles(state, ns);
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
BENCHMARK_CAPTURE(BM_Tick, all,
                  std::vector<std::string>{"servo_lag", "pneumatics", "shuttle_slip", "sensor_noise",
                                           "beat_contact", "inertia", "joint_friction"});
BENCHMARK(BM_RockerExactSolve);
BENCHMARK(BM_RockerTable)->RangeMultiplier(4)->Range(64, 65536);
BENCHMARK(BM_TickAfterSleep)->Arg(0)->Arg(50)->UseManualTime()->Iterations(sleep_iterations());
BENCHMARK(BM_CacheLinesAfterSleep)
    ->Arg(0)
    ->Arg(64)
    ->Arg(256)
    ->UseManualTime()
    ->Iterations(sleep_iterations());
BENCHMARK_MAIN();
