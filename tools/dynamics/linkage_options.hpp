// The builder's own beat-up for loom-dynamics beatup and balance: the thesis' loom by default, the
// [beatup] section of a loom config with --config FILE (the file loomctl reads), and any link length,
// branch, beater mass or link mass given explicitly on top. Offline-tool code (configure-time).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "loom/motion/dynamics.hpp"

namespace loom::dyncli {

struct LinkageArgs {
  std::string config;  // loom TOML; empty: the thesis' loom (Table 5.1)
  double crank_m = 0.0, coupler_m = 0.0, rocker_m = 0.0, ground_m = 0.0, beater_arm_m = 0.0;
  std::string branch, fell_at;
  double warp_depth_m = 0.0;
  double beater_kg = 2.5;
  double crank_kg = 0.0, coupler_kg = 0.0, rocker_kg = 0.0;  // bar masses; default: cast-iron bars
  double bar_width_m = 0.03, bar_thickness_m = 0.01, density_kg_m3 = motion::kCastIronDensity_kg_m3;
};

// Registers --config, the link lengths (m), --branch, --fell-at, --warp-depth-m, --beater-kg, the link
// masses and the bar section on `c`.
void add_linkage_options(CLI::App* c, LinkageArgs& a);

struct Linkage {
  motion::BeatUpGeometry geometry;
  motion::BeatUpMasses masses;
  std::optional<double> config_crank_speed_rad_s;    // from the config, when it names one
  std::optional<double> config_beat_force_target_n;  // from the config, when it names one
};

// The linkage the options describe (throws UsageError naming file:line:col for a bad config,
// MotionError naming the quantity for an impossible linkage).
Linkage make_linkage(const CLI::App& c, const LinkageArgs& a);

}  // namespace loom::dyncli
