// loom-safety — the safety property campaign as a command: random scenes x random faults, the simulated
// machine's true state checked every tick (see campaign.hpp). Prints `runs N, violations V`; each
// violating run's scene is written to --out DIR, replayable with `loomctl weave --scene FILE`.
// Exit 0 no violation, 1 a violation, 2 bad arguments.
#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "campaign.hpp"

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) {
  g_stop.store(true);
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"loom-safety — random scenes x random faults, the true machine state checked every tick"};
  loom::safety::CampaignOptions opt;
  std::string out = "safety-violations";
  bool seed_given = false;
  app.add_option("--runs", opt.runs, "number of random runs")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{100'000'000}));
  app.add_option_function<std::uint64_t>(
      "--seed", [&](const std::uint64_t& s) { opt.seed = s, seed_given = true; },
      "campaign seed (default: from the clock, printed)");
  app.add_option("--threads", opt.threads, "worker threads")->check(CLI::Range(1, 256));
  app.add_option("--rows", opt.rows, "rows woven per run")->check(CLI::Range(1u, 100u));
  app.add_option("--out", out, "directory for the scene files of violating runs");
  app.add_option("--config", opt.config_path,
                 "the loom description to weave on (default: the embedded default loom); e.g. one whose "
                 "io.<sensor>_2_bit = -1 has single-channel safety sensors");
  app.add_flag("--axis-jams", opt.axis_jams,
               "draw jammed core axes too (a drive that stops following without a fault of its own)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "loom-safety: %s\n", e.what());
    return 2;
  }
  if (!seed_given) {
    opt.seed = static_cast<std::uint64_t>(std::chrono::system_clock::now().time_since_epoch().count()) %
               1'000'000'007ull;
  }
  if (!opt.config_path.empty()) opt.config_path = std::filesystem::absolute(opt.config_path).string();
  std::printf(
      "loom-safety: seed %llu, %llu runs of %u rows, %d threads, loom %s%s (replay this campaign with --seed "
      "%llu%s)\n",
      static_cast<unsigned long long>(opt.seed), static_cast<unsigned long long>(opt.runs), opt.rows,
      opt.threads, opt.config_path.empty() ? "embedded default" : opt.config_path.c_str(),
      opt.axis_jams ? ", jammed axes drawn too" : "", static_cast<unsigned long long>(opt.seed),
      opt.axis_jams ? " --axis-jams" : "");
  std::fflush(stdout);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  const auto t0 = std::chrono::steady_clock::now();
  opt.stop = &g_stop;
  // Violations are reported (and their scenes written) as they are found; progress every 10 %.
  const auto write_scene = [&](const loom::safety::Violation& v) {
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    const std::string file =
        out + "/violation-" + std::to_string(opt.seed) + "-" + std::to_string(v.run) + ".toml";
    std::ofstream f(file);
    f << "# loom-safety seed " << opt.seed << " run " << v.run << ": " << v.description << "\n# " << v.what
      << "\n# replay: loomctl weave --scene " << file << " --rows " << opt.rows << " --no-telemetry\n"
      << v.scene_toml;
    std::printf("VIOLATION run %llu (%s): %s\n  scene: %s%s\n", static_cast<unsigned long long>(v.run),
                v.description.c_str(), v.what.c_str(), file.c_str(), f ? "" : " (could not be written)");
    std::fflush(stdout);
  };
  const std::uint64_t tenth = std::max<std::uint64_t>(1, opt.runs / 10);
  opt.on_run = [&](const loom::safety::CampaignResult& so_far, const loom::safety::Violation* v) {
    if (v != nullptr) write_scene(*v);
    if (so_far.runs % tenth == 0 && so_far.runs < opt.runs) {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "loom-safety: %llu/%llu runs, %zu violations, %.0f s\n",
                   static_cast<unsigned long long>(so_far.runs), static_cast<unsigned long long>(opt.runs),
                   so_far.violations.size(), s);
    }
  };
  loom::safety::CampaignResult r;
  try {
    r = loom::safety::run_campaign(opt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loom-safety: %s\n", e.what());
    return 2;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "runs %llu, violations %zu (%llu ended in a fault, %llu completed, %llu power cuts) in %.1f s, %.0f "
      "runs/s\n",
      static_cast<unsigned long long>(r.runs), r.violations.size(),
      static_cast<unsigned long long>(r.faulted), static_cast<unsigned long long>(r.completed),
      static_cast<unsigned long long>(r.power_cuts), wall,
      static_cast<double>(r.runs) / std::max(wall, 1e-9));
  if (g_stop.load())
    std::printf("loom-safety: interrupted after %llu runs\n", static_cast<unsigned long long>(r.runs));
  return r.violations.empty() ? 0 : 1;
}
