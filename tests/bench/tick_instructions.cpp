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
// --digest adds a hash of what every tick read, commanded and published (the values, field by field):
// an optimisation that keeps behaviour identical keeps the digest of every scene.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <thread>

#include "loom/config/config.hpp"
#include "loom/config/scene_config.hpp"
#include "loom/firmware/machine.hpp"
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

// FNV-1a over values (not struct bytes: padding is not behaviour).
struct Digest {
  std::uint64_t h = 0xcbf29ce484222325ull;
  template <typename T>
  void add(const T& v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    for (unsigned char c : b) h = (h ^ c) * 0x100000001b3ull;
  }
  void add_name(const char* s) {
    for (; *s != '\0'; ++s) add(*s);
    add('\0');
  }
};

void digest_tick(Digest& d, const firmware::ControlLoop& loop, std::size_t n_axes, bool telemetry) {
  const hal::HalInputs& in = loop.inputs();
  const hal::HalOutputs& out = loop.outputs();
  for (std::size_t i = 0; i < n_axes; ++i) {
    const hal::AxisFeedback& a = in.axes[i];
    d.add(a.state), d.add(a.position), d.add(a.velocity), d.add(a.effort), d.add(a.fault_code);
    d.add(a.fault_kind), d.add(a.fault), d.add(a.following_error), d.add(a.referenced), d.add(a.homing_error);
    d.add(a.refreshed);
    d.add(out.axes[i].request), d.add(out.axes[i].target_position);
  }
  const hal::DigitalInputs& io = in.io;
  d.add(io.piston_a_extended), d.add(io.piston_a_retracted), d.add(io.piston_b_extended);
  d.add(io.piston_b_retracted), d.add(io.shuttle_at_left), d.add(io.shuttle_at_right), d.add(io.estop_ok);
  for (bool b : io.second_channel) d.add(b);
  d.add(io.refreshed), d.add(in.analog.beat_force_n), d.add(in.analog.beat_force_valid),
      d.add(in.analog.refreshed);
  d.add(in.link.link_fault), d.add(in.link.link_fault_code), d.add(in.link.recovery);
  d.add(out.io.piston_a_extend), d.add(out.io.piston_b_extend), d.add(out.io.lamp_green),
      d.add(out.io.lamp_amber);
  d.add(out.io.lamp_red), d.add(out.io.buzzer);
  if (!telemetry) return;
  const telemetry::Snapshot& s = loop.snapshot();
  // The names, as the snapshot carried them before it carried the enums (digests compare across that).
  const bool faulted = s.first_fault != 0;
  d.add(s.tick), d.add_name(sequencer::state_name(static_cast<sequencer::State>(s.state)));
  d.add_name(faulted ? sequencer::fault_name(static_cast<sequencer::Fault>(s.first_fault)) : "");
  d.add_name(faulted ? sequencer::fault_name(static_cast<sequencer::Fault>(s.stopped_by)) : "");
  d.add(s.row), d.add(s.pick), d.add(s.beat), d.add(s.row_in_progress), d.add(s.crank_phase_rad);
  d.add(s.beater_angle_rad), d.add(s.beat_force_n), d.add(s.axis_count), d.add(s.inputs), d.add(s.inputs_2);
  d.add(s.outputs), d.add(s.fault_axis), d.add(s.fault_tick);
  for (std::size_t i = 0; i < n_axes; ++i) {
    d.add(s.axes[i].position), d.add(s.axes[i].target), d.add(s.axes[i].following_error),
        d.add(s.axes[i].request);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Runs the control loop for a fixed number of ticks; run it under callgrind with "
      "--collect-atstart=no --toggle-collect=measured_tick (tests/bench/tick_instructions.sh)"};
  std::string config_path, scene_path, lcm_url = "memq://";
  bool telemetry = false, digest = false;
  long long warmup = 4000, ticks = 4000;
  app.add_option("--config", config_path, "loom config file (default: the embedded default loom)");
  app.add_option("--scene", scene_path, "scene file (default: the embedded default scene)");
  app.add_flag("--telemetry", telemetry, "publish telemetry (lossless, as in virtual time)");
  app.add_flag("--digest", digest,
               "print a hash of every tick's inputs, outputs and snapshot (not for callgrind)");
  app.add_option("--lcm-url", lcm_url, "LCM URL for --telemetry")->capture_default_str();
  app.add_option("--warmup", warmup, "ticks woven before measuring")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--ticks", ticks, "ticks measured")->capture_default_str()->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    firmware::LoomConfig cfg =
        config_path.empty() ? firmware::default_loom_config() : firmware::load_loom_config(config_path);
    cfg.telemetry.lcm_url = lcm_url;
    const firmware::Scene scene =
        scene_path.empty() ? firmware::default_scene() : firmware::load_scene(scene_path);
    firmware::MachineOptions opt;
    opt.telemetry = telemetry;
    opt.lossless_telemetry = true;
    opt.rows = 1'000'000;  // never finishes within the measured ticks
    firmware::Machine m(cfg, scene, opt, {});
    m.sequencer().request_start();
    firmware::ControlLoop& loop = m.loop();
    const std::size_t n_axes = m.sequencer().axes().count;
    Digest d;
    hal::Tick t = 0;
    for (; t < warmup; ++t) {
      wait_for_room(loop);
      loop.cycle(t);
      if (digest) digest_tick(d, loop, n_axes, telemetry);
    }
    for (const hal::Tick end = t + ticks; t < end; ++t) {
      wait_for_room(loop);
      measured_tick(&loop, t);
      if (digest) digest_tick(d, loop, n_axes, telemetry);
    }
    const sequencer::Counters& c = m.sequencer().counters();
    std::printf("ticks %lld axes %zu state %s fault %s rows %u picks %u beats %u\n", ticks,
                m.sequencer().axes().count, sequencer::state_name(m.sequencer().state()),
                sequencer::fault_name(m.sequencer().first_fault()), c.rows, c.picks, c.beats);
    if (digest) std::printf("digest %016llx\n", static_cast<unsigned long long>(d.h));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loom_bench_tick_instructions: %s\n", e.what());
    return 2;
  }
}
