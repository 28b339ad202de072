// loom-plot — redraw a run's plots from its summary.json (beat force across the width, row timeline),
// e.g. after editing or merging summaries, or for a summary copied off a loom controller.
//   loom-plot --summary DIR/summary.json [--out DIR]
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "loom/report/run_report.hpp"

int main(int argc, char** argv) {
  CLI::App app{"loom-plot — plots of a loomctl run report"};
  std::string summary, out;
  app.add_option("--summary", summary, "summary.json written by loomctl weave --report")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", out, "output directory (default: next to the summary)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "loom-plot: %s\n", e.what());
    return 2;
  }
  if (out.empty()) out = std::filesystem::path(summary).parent_path().string();
  if (out.empty()) out = ".";
  nlohmann::json j;
  try {
    std::filesystem::create_directories(out);
    std::ifstream f(summary);
    j = nlohmann::json::parse(f);
    loom::report::write_plots(j, out);
  } catch (const nlohmann::json::exception& e) {
    std::fprintf(stderr, "loom-plot: %s: not a loomctl summary: %s\n", summary.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loom-plot: %s\n", e.what());
    return 1;
  }
  std::printf("loom-plot: wrote %s/beat_force.svg and %s/row_timeline.svg\n", out.c_str(), out.c_str());
  return 0;
}
