// `loomctl design fit IN.png|IN.csv --loom LOOM.toml [--tile | --scale | --centre --ground CODE]
// [--palette-from-magazines] [--max-delta-e X] --out OUT.csv [--preview OUT.png]`: a picture a weaver
// brings, fitted to this loom's knots per row, its colours mapped to the loom's yarns (nearest in
// CIELAB, CIEDE2000 printed per colour, every unmapped colour listed at once), written as a design CSV
// with a preview at the carpet's true aspect. Moves nothing; offline (reads the loom config only).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "loom/design/design_fit.hpp"

namespace loom::firmware {

struct DesignFitArgs {
  std::string action;  // "fit"
  std::string picture, loom, out, preview, ground;
  bool tile = false, scale = false, centre = false, palette_from_magazines = false;
  double max_delta_e = design::kDefaultMaxDeltaE;
};

// Exit code: 0 written; 2 refused (the error names file:line:col or the pixel, option or key, and value;
// every unmapped colour at once) with nothing written.
int run_design_fit(const DesignFitArgs& a);

// Adds `design` to `app`; after app.parse(), run() executes it and returns its exit code, or nullopt when
// another subcommand was chosen.
class DesignCommand {
 public:
  explicit DesignCommand(CLI::App& app);
  std::optional<int> run() const;

 private:
  CLI::App* cmd_;
  DesignFitArgs args_;
};

}  // namespace loom::firmware
