// The subcommands of loom-dynamics: each registers its options on the CLI11 app and runs from the
// parsed values. Runs throw MotionError for impossible designs and UsageError for bad combinations
// of options; main() turns both into a message on stderr and exit status 2.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "linkage_options.hpp"
#include "loom/cli/run.hpp"

namespace loom::dyncli {

using cli::UsageError;

struct BeatupArgs {
  double crank_rad_s = 0.0;
  double target_force_n = 0.0;
  int samples = 360;
  double contact_n = 0.0;
  double gravity_deg = -90.0;  // direction of gravity in the linkage frame (A0->B0 = 0 deg)
  double cam_e = 0.0;          // elliptic-gear crank law (electronic cam), 0 = constant speed
  double cam_phi02_rad = 0.0;
  std::string svg;
  bool extra = false;
  LinkageArgs linkage;
};
CLI::App* add_beatup(CLI::App& app, BeatupArgs& a);
void run_beatup(const CLI::App& cmd, const BeatupArgs& a);

struct NeedleArgs {
  int samples = 360;
  double rpm = 160.0;
  double friction_n = 1000.0;
  std::string rocker_side = "away";  // 002's assembly (see loom-kin needle)
  std::string rod_side = "hanging";
  std::string svg;
};
CLI::App* add_needle(CLI::App& app, NeedleArgs& a);
void run_needle(const NeedleArgs& a);

struct BattenArgs {
  double e = 0.2;
  double phi02_rad = 0.0;
  bool search = false;
  bool scan = false;
  std::string side = "front";
  int k = 2;
  double omega1_rad_s = 1.0;
  int samples = 720;
  int scan_points = 360;
};
CLI::App* add_batten(CLI::App& app, BattenArgs& a);
void run_batten(const CLI::App& cmd, const BattenArgs& a);

struct BalanceArgs {
  double w1 = 0.5, w2 = 0.5;
  std::string method = "both";
  double crank_rad_s = 15.5;
  int samples = 360;
  double max_counterweight_kg = 10.0;
  double counterweight_thickness_m = 0.02;
  double xtol_rel = 1e-10;
  int max_evaluations = 4000;
  std::string trace;
  std::string svg_force, svg_moment;
  LinkageArgs linkage;
};
CLI::App* add_balance(CLI::App& app, BalanceArgs& a);
void run_balance(const CLI::App& cmd, const BalanceArgs& a);

CLI::App* add_mass(CLI::App& app);
void run_mass();

struct EquimomentalArgs {
  double mass_kg = 0.0, centre_d_m = 0.0, centre_theta_deg = 0.0, inertia_kg_m2 = 0.0;
  double offset_deg = 0.0;  // used when given; otherwise the points face the mass centre
  std::string table = "original";
};
CLI::App* add_equimomental(CLI::App& app, EquimomentalArgs& a);
void run_equimomental(const CLI::App& cmd, const EquimomentalArgs& a);

}  // namespace loom::dyncli
