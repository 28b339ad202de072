// The control loop with every thread it runs beside, for ThreadSanitizer (cmake --preset tsan): the
// loop paced in real time (faster than real time) on the simulated loom, LCM telemetry on with its
// publisher thread (udpm loopback, random port, ttl=0), the runner's reporter thread consuming run
// events, and a recipe-swap thread publishing new recipes through Machine::publish_recipe and collecting
// the retired ones while the loop weaves. TSan must report nothing (it fails the test with exit 66);
// the test also checks the run itself: every row woven and reported in order, a swapped recipe adopted.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"

namespace loom::firmware {
namespace {

// The embedded default loom with its beat-force target replaced by a fixed crank speed: a recipe
// change the running loop may adopt between rows.
LoomConfig recipe_with_crank_speed(double rad_s) {
  std::string text = kDefaultLoomToml;
  const std::string key = "beat_force_target_n = 90.0";
  const auto at = text.find(key);
  if (at == std::string::npos) throw std::runtime_error("default config lacks '" + key + "'");
  text.replace(at, key.size(), "crank_speed_rad_s = " + std::to_string(rad_s));
  return parse_loom_config(text, "<recipe " + std::to_string(rad_s) + " rad/s>");
}

TEST(LoopThreads, LoopPublisherReporterAndRecipeSwapsShareNoUnsynchronisedState) {
  std::random_device rd;
  const unsigned seed =
      std::getenv("LOOM_TSAN_SEED") ? static_cast<unsigned>(std::stoul(std::getenv("LOOM_TSAN_SEED"))) : rd();
  std::mt19937 rng(seed);
  const int port = std::uniform_int_distribution<int>(20000, 60000)(rng);
  std::printf("seed %u (LOOM_TSAN_SEED), LCM port %d\n", seed, port);

  LoomConfig cfg = default_loom_config();
  cfg.telemetry.lcm_url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
  cfg.loom_id = "tsan" + std::to_string(port);
  const std::vector<LoomConfig> recipes = {recipe_with_crank_speed(14.0), recipe_with_crank_speed(15.0),
                                           recipe_with_crank_speed(17.0)};
  // The same recipes with the running loop's identity and run settings (a reload may change only the
  // recipe; loomctl carries its command-line overrides over the same way).
  std::vector<LoomConfig> published;
  for (LoomConfig r : recipes) {
    r.loom_id = cfg.loom_id;
    r.telemetry = cfg.telemetry;
    published.push_back(r);
  }

  MachineOptions mo;
  mo.telemetry = true;
  mo.lossless_telemetry = false;  // real-time semantics: a full ring drops, never waits
  constexpr std::uint32_t kRows = 3;
  mo.rows = kRows;
  Machine m(cfg, default_scene(), mo, sequencer::Counters{});
  ASSERT_NE(m.telemetry(), nullptr);
  const double initial_speed = m.profiles().spec().crank.velocity;

  std::atomic<bool> run_over{false};
  std::atomic<int> swaps{0};
  std::thread swapper([&] {
    std::size_t k = 0;
    while (!run_over.load(std::memory_order_acquire)) {
      m.publish_recipe(published[k++ % published.size()]);
      m.collect_retired_recipes();
      swaps.fetch_add(1, std::memory_order_relaxed);
      std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(5, 40)(rng)));
    }
    m.collect_retired_recipes();
  });

  std::vector<RunEvent> events;  // touched by the reporter thread only while the loop runs
  RunOptions ro;
  ro.period_s = cfg.sequencer.period_s;
  ro.realtime = true;  // the reporter thread exists only in real time
  ro.pace = 25.0;
  ro.grace_ticks = 50;
  ro.max_ticks = static_cast<hal::Tick>(kRows * 30.0 / cfg.sequencer.period_s);  // a safety net, ~10x a row
  m.sequencer().request_start();
  const RunResult res =
      run_loop(m.loop(), m.sequencer(), ro, [&](const RunEvent& e) { events.push_back(e); });
  run_over.store(true, std::memory_order_release);
  swapper.join();
  m.telemetry()->stop();

  EXPECT_EQ(m.sequencer().state(), sequencer::State::kDone);
  EXPECT_EQ(m.sequencer().counters().rows, kRows);
  std::vector<std::uint32_t> rows_reported;
  for (const RunEvent& e : events) {
    if (e.kind == RunEvent::Kind::kRowDone) rows_reported.push_back(e.counters.rows);
  }
  EXPECT_EQ(rows_reported, (std::vector<std::uint32_t>{1, 2, 3}));
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().kind, RunEvent::Kind::kFinished);
  EXPECT_GT(swaps.load(), 0);
  const double final_speed = m.sequencer().profiles().spec().crank.velocity;
  EXPECT_NE(final_speed, initial_speed) << "no published recipe was adopted at a row boundary";
  const telemetry::PublisherStats st = m.telemetry()->stats();
  EXPECT_GT(st.status, 0u);
  EXPECT_GT(st.axes, 0u);
  std::printf(
      "ticks %lld in %.2f s wall, %d recipe swaps, crank %.2f -> %.2f rad/s, LCM status %llu axes %llu, "
      "publish errors %llu, dropped %llu\n",
      static_cast<long long>(res.ticks), res.wall_s, swaps.load(), initial_speed, final_speed,
      static_cast<unsigned long long>(st.status), static_cast<unsigned long long>(st.axes),
      static_cast<unsigned long long>(st.publish_errors),
      static_cast<unsigned long long>(m.telemetry()->dropped()));
}

}  // namespace
}  // namespace loom::firmware
