// What a control tick costs in instructions: the harness tests/bench/tick_instructions.sh runs under
// callgrind. It assembles the loom exactly as `loomctl weave` does (Machine: the sim HAL, the
// sequencer, telemetry on or off, the control loop), weaves `--warmup` ticks (bring-up and into the
// first rows, not measured), then `--ticks` more, each through measured_tick(): callgrind is started
// with --collect-atstart=no --toggle-collect=measured_tick, so it counts exactly those ticks'
// ControlLoop::cycle (plus the call into it) and nothing of the set-up, the warm-up, or the telemetry
// publisher's own thread. Instructions per tick = callgrind's total / --ticks.
//
// Telemetry on is what a virtual-time run does: lossless, the loop waits for ring room before each tick
// (outside the measured call, as the runner does), so the tick itself never waits. Its LCM URL defaults
// to memq:// (in-process): what the publisher thread does with a snapshot is not the tick's cost.
//
// Without valgrind the program just runs (a quick check that the harness works); it prints the ticks it
// measured and the sequencer's state and counters, so a run that faulted or stopped is visible.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>
#include <thread>

#include "loom/firmware/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/scene_config.hpp"
#include "loom/hal/types.hpp"
#include "loom/sequencer/sequencer.hpp"

using namespace loom;

// Not inlined, so callgrind's --toggle-collect finds it by name. Collection is on while it runs.
extern "C" __attribute__((noinline)) void measured_tick(firmware::ControlLoop* loop, hal::Tick t) {
  loop->cycle(t);
  asm volatile("" ::: "memory");  // keep the call a real call
}

namespace {

// The runner's wait before a virtual-time tick (a snapshot and the most events a tick can push).
void wait_for_room(firmware::ControlLoop& loop) {
  telemetry::Telemetry* t = loop.lossless_telemetry();
  if (t == nullptr) return;
  while (!t->has_room(3 + hal::kMaxAxes) && t->publishing()) std::this_thread::yield();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Runs the control loop for a fixed number of ticks; run it under callgrind with "
               "--collect-atstart=no --toggle-collect=measured_tick (tests/bench/tick_instructions.sh)"};
  std::string config_path, scene_path, lcm_url = "memq://";
  bool telemetry = false;
  long long warmup = 4000, ticks = 4000;
  app.add_option("--config", config_path, "loom config file (default: the embedded default loom)");
  app.add_option("--scene", scene_path, "scene file (default: the embedded default scene)");
  app.add_flag("--telemetry", telemetry, "publish telemetry (lossless, as in virtual time)");
  app.add_option("--lcm-url", lcm_url, "LCM URL for --telemetry")->capture_default_str();
  app.add_option("--warmup", warmup, "ticks woven before measuring")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--ticks", ticks, "ticks measured")->capture_default_str()->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    firmware::LoomConfig cfg =
        config_path.empty() ? firmware::default_loom_config() : firmware::load_loom_config(config_path);
    cfg.telemetry.lcm_url = lcm_url;
    const firmware::Scene scene = scene_path.empty() ? firmware::default_scene() : firmware::load_scene(scene_path);
    firmware::MachineOptions opt;
    opt.telemetry = telemetry;
    opt.lossless_telemetry = true;
    opt.rows = 1'000'000;  // never finishes within the measured ticks
    firmware::Machine m(cfg, scene, opt, {});
    m.sequencer().request_start();
    firmware::ControlLoop& loop = m.loop();
    hal::Tick t = 0;
    for (; t < warmup; ++t) {
      wait_for_room(loop);
      loop.cycle(t);
    }
    for (const hal::Tick end = t + ticks; t < end; ++t) {
      wait_for_room(loop);
      measured_tick(&loop, t);
    }
    const sequencer::Counters& c = m.sequencer().counters();
    std::printf("ticks %lld axes %zu state %s fault %s rows %u picks %u beats %u\n", ticks,
                m.sequencer().axes().count, sequencer::state_name(m.sequencer().state()),
                sequencer::fault_name(m.sequencer().first_fault()), c.rows, c.picks, c.beats);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loom_bench_tick_instructions: %s\n", e.what());
    return 2;
  }
}
