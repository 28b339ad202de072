// loom-dynamics needle: the tufting-needle six-bar of seed 002 (Table 1 geometry, masses and
// inertias, β1 = 168°) over one main-shaft turn: balancing torque and every joint reaction.
#include <string>

#include "commands.hpp"
#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/dynamics_needle.hpp"
#include "svg_plot.hpp"

namespace loom::dyncli {

using namespace loom::motion;

CLI::App* add_needle(CLI::App& app, NeedleArgs& a) {
  CLI::App* c = app.add_subcommand(
      "needle", "Needle six-bar (002) balancing torque and joint reactions over a turn (CSV)");
  c->add_option("--samples", a.samples, "Samples over one main-shaft turn")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  c->add_option("--rpm", a.rpm, "Main-shaft speed (002's experiment: 160 r/min)")
      ->check(cli::positive_number())
      ->capture_default_str();
  c->add_option("--friction-n", a.friction_n, "Backing friction on the needle, against its motion")
      ->check(cli::non_negative_number())
      ->capture_default_str();
  c->add_option("--rocker-side", a.rocker_side,
                "Rocker pin B away from the needle side of O-C (002) or toward it")
      ->check(CLI::IsMember({"away", "toward"}))
      ->capture_default_str();
  c->add_option("--rod-side", a.rod_side,
                "Rod D-E hanging down to the needle bar (002) or standing above it (mirror)")
      ->check(CLI::IsMember({"hanging", "standing"}))
      ->capture_default_str();
  c->add_option("--svg", a.svg,
                "Also plot the balancing torque and main reactions vs shaft angle to this SVG file");
  return c;
}

void run_needle(const NeedleArgs& a) {
  NeedleBranch branch;
  branch.rocker =
      a.rocker_side == "toward" ? NeedleRockerSide::kPinTowardNeedle : NeedleRockerSide::kPinAwayFromNeedle;
  branch.rod = a.rod_side == "standing" ? NeedleRodSide::kStandingRod : NeedleRodSide::kHangingRod;
  const NeedleLinkage linkage(needle_table1(), branch);
  const NeedleMasses masses = needle_table1_masses();
  NeedleLoads loads;
  loads.friction_n = a.friction_n;
  const double omega1 = a.rpm * kTwoPi / 60.0;
  cli::CsvWriter out(
      "theta1_deg,balancing_torque_nm,pin_o_n,pin_a_n,pin_b_n,pin_c_n,pin_d_n,pin_e_n,guide_n,weld_torque_nm,"
      "friction_n");
  const bool plot = !a.svg.empty();
  Chart chart{"Needle six-bar at " + cli::format_number(a.rpm) + " r/min",
              "main-shaft angle (deg)",
              "N m, N / 100",
              {},
              {}};
  chart.series = {{"balancing torque (N m)", {}}, {"pin O (N/100)", {}}, {"pin C (N/100)", {}}};
  needle_sweep(linkage, a.samples, omega1, [&](const NeedleState& st) {
    const NeedleForces f = needle_inverse_dynamics(linkage, masses, st, loads);
    const double th = deg(f.state.theta1_rad);
    out.num(th).num(f.balancing_torque_nm).num(f.pin_o_n.norm()).num(f.pin_a_n.norm()).num(f.pin_b_n.norm());
    out.num(f.pin_c_n().norm())
        .num(f.pin_d_n.norm())
        .num(f.pin_e_n.norm())
        .num(f.guide_n)
        .num(f.weld_torque_nm);
    out.num(f.friction_n);
    out.end_row();
    if (plot) {
      chart.x.push_back(th);
      chart.series[0].y.push_back(f.balancing_torque_nm);
      chart.series[1].y.push_back(f.pin_o_n.norm() / 100.0);
      chart.series[2].y.push_back(f.pin_c_n().norm() / 100.0);
    }
  });
  if (plot && !write_svg(chart, a.svg)) throw UsageError("--svg: cannot write '" + a.svg + "'");
  out.finish();
}

}  // namespace loom::dyncli
