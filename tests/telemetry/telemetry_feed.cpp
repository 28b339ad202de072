// Test driver for the script tests: plays the scripted weaving run (synthetic_loom.hpp) through a real
// Telemetry publisher at a loop-like pace, then prints what it published so a script can check that
// lcm-logger recorded, and loom-monitor replayed, exactly that.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "loom/telemetry/telemetry.hpp"
#include "synthetic_loom.hpp"

int main(int argc, char** argv) {
  loom::telemetry::PublisherConfig cfg;
  std::int64_t rows = 3;
  std::int64_t tick_us = 200;
  CLI::App app{"Publish a scripted weaving run as loom telemetry (test driver)."};
  app.add_option("--lcm-url", cfg.lcm_url, "LCM URL")->required();
  app.add_option("--loom-id", cfg.loom_id, "Loom id")->required();
  app.add_option("--rows", rows, "Rows to weave")->check(CLI::Range(1, 10000));
  app.add_option("--tick-us", tick_us, "Wall-clock microseconds per tick")->check(CLI::Range(0, 1000000));
  app.add_option("--axes-every", cfg.decimation.axes_every_n_ticks, "AXES every n ticks");
  app.add_option("--rt-every", cfg.decimation.rt_every_n_ticks, "RT every n ticks");
  app.add_option("--max-rate", cfg.max_messages_per_s, "Publisher pacing, messages/s (0: none)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  const loom::telemetry::test_support::WeaveScript w;
  try {
    loom::telemetry::Telemetry tel(cfg);
    tel.start();
    // One tick past the last row so the final row count is published.
    const std::int64_t ticks = w.ticks_for_rows(rows) + 1;
    auto next = std::chrono::steady_clock::now();
    for (std::int64_t t = 0; t < ticks; ++t) {
      tel.push_waiting(loom::telemetry::test_support::script_snapshot(w, t));
      next += std::chrono::microseconds(tick_us);
      std::this_thread::sleep_until(next);
    }
    tel.stop();
    const auto st = tel.stats();
    std::printf("published snapshots=%llu status=%llu axes=%llu rt=%llu dropped=%llu errors=%llu\n",
                static_cast<unsigned long long>(st.snapshots), static_cast<unsigned long long>(st.status),
                static_cast<unsigned long long>(st.axes), static_cast<unsigned long long>(st.rt),
                static_cast<unsigned long long>(tel.dropped()),
                static_cast<unsigned long long>(st.publish_errors));
    return st.publish_errors == 0 && tel.dropped() == 0 ? 0 : 1;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "telemetry_feed: %s\n", e.what());
    return 2;
  }
}
