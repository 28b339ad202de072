// loom-synth: the thesis' dimensional synthesis for loom builders — Söylemez slider-crank and
// Khare–Dave crank-rocker tables as CSV, and a one-row beat-up linkage design. CSV on stdout,
// notes and errors on stderr; bad arguments or impossible designs exit 2 naming the argument.
#include <CLI/CLI.hpp>
#include <iostream>
#include <stdexcept>

#include "commands.hpp"

int main(int argc, char** argv) {
  using namespace loom::synth;
  CLI::App app{
      "Dimensional synthesis of the beat-up linkage (thesis 000 §4.5). Angles in degrees; "
      "lengths relative to ground = 1 (crank-rocker) or stroke = 1 (slider-crank) unless "
      "given."};
  app.require_subcommand(1);

  SliderCrankArgs sc;
  CLI::App* sc_cmd =
      app.add_subcommand("slider-crank",
                         "Söylemez slider-crank for a crank rotation phi between dead centres: "
                         "phi_deg,a,b,c,mu_min_deg,lambda (Table 4.2)");
  CLI::Option* sc_phi = sc_cmd->add_option("--phi", sc.phi_deg, "Crank rotation, 90 <= phi < 180 deg")
                            ->each([&sc](const std::string& v) { sc.phi_text = v; });
  CLI::Option* sc_range =
      sc_cmd->add_option("--phi-range", sc.phi_range, "Table of phi: first:last[:step] deg, e.g. 90:179");
  sc_phi->excludes(sc_range);
  sc_cmd->add_option("--stroke", sc.stroke, "Slider stroke; lengths come out in its unit")
      ->capture_default_str();
  CLI::Option* sc_lambda =
      sc_cmd->add_option("--lambda", sc.lambda, "Crank/coupler ratio a/b (default: optimum lambda)");
  sc_cmd->add_flag("--full-precision", sc.full_precision, "Print %.17g instead of the thesis' digits");

  CrankRockerArgs cr;
  CLI::App* cr_cmd =
      app.add_subcommand("crank-rocker",
                         "Khare-Dave crank-rocker for swing psi and crank rotation phi: "
                         "beta_deg,a,b,c,mu_min_deg, one row per integer beta (Tables 4.6-4.9)");
  cr_cmd->add_option("--psi", cr.psi_deg, "Rocker swing angle, 0 < psi < 180 deg")->required();
  cr_cmd->add_option("--phi", cr.phi_deg, "Crank rotation from extended to folded dead centre, deg")
      ->required()
      ->each([&cr](const std::string& v) { cr.phi_text = v; });
  CLI::Option* cr_beta =
      cr_cmd->add_option("--beta", cr.beta_deg, "Crank angle at the extended dead centre (one design)");
  cr_cmd->add_option("--ground", cr.ground, "Ground link length; lengths come out in its unit")
      ->capture_default_str();
  cr_cmd->add_flag("--full-precision", cr.full_precision, "Print %.17g instead of the thesis' digits");

  DesignArgs ds;
  CLI::App* ds_cmd = app.add_subcommand(
      "design", "One beat-up linkage: --stroke S gives a slider-crank, --swing PSI a crank-rocker");
  CLI::Option* ds_stroke = ds_cmd->add_option("--stroke", ds.stroke, "Beater stroke (slider-crank)");
  CLI::Option* ds_swing = ds_cmd->add_option("--swing", ds.swing_deg, "Rocker swing psi, deg (crank-rocker)");
  ds_stroke->excludes(ds_swing);
  ds_cmd->add_option("--phi", ds.phi_deg, "Crank rotation between dead centres, deg")
      ->required()
      ->each([&ds](const std::string& v) { ds.phi_text = v; });
  CLI::Option* ds_lambda = ds_cmd->add_option(
      "--lambda", ds.lambda, "Crank/coupler ratio a/b (default: the design maximising mu_min)");
  CLI::Option* ds_beta =
      ds_cmd->add_option("--beta", ds.beta_deg, "Crank-rocker: crank angle at the extended dead centre, deg");
  ds_cmd->add_option("--ground", ds.ground, "Crank-rocker: ground link length")->capture_default_str();
  ds_cmd->add_flag("--thesis-rounding", ds.thesis_rounding,
                   "Slider-crank: scale the 6-decimal unit-stroke design, as the thesis' Table 4.3 did");
  ds_cmd->add_flag("--full-precision", ds.full_precision, "Print %.17g instead of the thesis' digits");

  ThreePointArgs tp;
  CLI::App* tp_cmd = app.add_subcommand(
      "three-point",
      "Three-precision-point synthesis of the knotting chain (seed 001): "
      "lambda,a0,a1,a2,theta1_i_deg,closure_residual, one row per real solution (mm, deg)");
  tp_cmd->add_option("--theta0-deg", tp.theta0_deg, "Fixed angle of the first link A0-O1, degrees")
      ->required();
  tp_cmd
      ->add_option("--point", tp.points,
                   "Precision point RX,RY,THETA2 (mm, mm, last link's angle in degrees); three times")
      ->required();
  tp_cmd->add_flag("--full-precision", tp.full_precision, "Print %.17g instead of 6 decimals");

  KnotterArgs kn;
  CLI::App* kn_cmd = app.add_subcommand(
      "knotter",
      "Seed 001's knotting four-bar from the two three-point chains (shared coupler), checked "
      "for branch, order, transmission and toggles, as [knotting.linkage] config lines (SI)");
  kn_cmd->add_option("--theta0-deg", kn.theta0_deg, "Fixed-link direction of the synthesis, degrees")
      ->capture_default_str();
  kn_cmd->add_option("--point", kn.points,
                     "Precision point RX,RY,THETA2 (mm, mm, deg): TAKE, WRAP, PULL (default seed 001's)");
  kn_cmd->add_option("--warp-entry-mm", kn.warp_entry_mm, "Gripper inside the warp while its x >= this (mm)")
      ->capture_default_str();
  kn_cmd
      ->add_option("--min-transmission-deg", kn.min_transmission_deg,
                   "Least transmission angle allowed in the stroke")
      ->capture_default_str();
  kn_cmd->add_option("--drive", kn.drive, "Which chain's side link the servo drives: auto, first, second")
      ->capture_default_str();
  kn_cmd->add_option("--max-speed-rad-s", kn.max_speed_rad_s,
                     "Servo speed cap below its no-load speed, for the cycle-time comment (default: none)");
  kn_cmd->add_option("--no-load-speed-rad-s", kn.no_load_speed_rad_s,
                     "Servo no-load speed at the output (default: the shipped 100 W servo behind 10:1)");
  kn_cmd->add_option("--max-torque-nm", kn.max_torque_nm, "Servo peak torque at the output");

  return loom::cli::run_cli("loom-synth", app, argc, argv, [&] {
    if (*sc_cmd) {
      sc.has_phi = sc_phi->count() > 0;
      sc.has_lambda = sc_lambda->count() > 0;
      run_slider_crank(sc, std::cout, std::cerr);
    } else if (*cr_cmd) {
      cr.has_beta = cr_beta->count() > 0;
      run_crank_rocker(cr, std::cout, std::cerr);
    } else if (*ds_cmd) {
      ds.has_stroke = ds_stroke->count() > 0;
      ds.has_swing = ds_swing->count() > 0;
      ds.has_lambda = ds_lambda->count() > 0;
      ds.has_beta = ds_beta->count() > 0;
      run_design(ds, std::cout, std::cerr);
    } else if (*tp_cmd) {
      run_three_point(tp, std::cout, std::cerr);
    } else if (*kn_cmd) {
      run_knotter(kn, std::cout, std::cerr);
    }
    std::cout.flush();
    if (!std::cout) throw std::runtime_error("cannot write the CSV output");
  });
}
