// loom-dynamics needle: the tufting-needle six-bar of seed 002 (Table 1 geometry, masses and
// inertias, β1 = 168°) over one main-shaft turn: balancing torque and every joint reaction.
#include <string>

#include "checks.hpp"
#include "commands.hpp"
#include "csv.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/dynamics_needle.hpp"
#include "svg_plot.hpp"

namespace loom::dyncli {

using namespace loom::motion;

CLI::App* add_needle(CLI::App& app, NeedleArgs& a) {
  CLI::App* c = app.add_subcommand("needle", "Needle six-bar (002) balancing torque and joint reactions over a turn (CSV)");
  c->add_option("--samples", a.samples, "Samples over one main-shaft turn")->check(CLI::Range(1, 10000000))->capture_default_str();
  c->add_option("--rpm", a.rpm, "Main-shaft speed (002's experiment: 160 r/min)")->check(positive_number())->capture_default_str();
  c->add_option("--friction-n", a.friction_n, "Backing friction on the needle, against its motion")
      ->check(non_negative_number())->capture_default_str();
  c->add_option("--svg", a.svg, "Also plot the balancing torque and main reactions vs shaft angle to this SVG file");
  return c;
}

void run_needle(const NeedleArgs& a) {
  const NeedleLinkage linkage(needle_table1());
  NeedleLoads loads;
  loads.friction_n = a.friction_n;
  const double omega1 = a.rpm * kTwoPi / 60.0;
  const std::vector<NeedleForces> sw = needle_dynamics_sweep(linkage, needle_table1_masses(), a.samples, omega1, loads);
  std::string out =
      "theta1_deg,balancing_torque_nm,pin_o_n,pin_a_n,pin_b_n,pin_c_n,pin_d_n,pin_e_n,guide_n,weld_torque_nm,"
      "friction_n\n";
  Chart chart{"Needle six-bar at " + format_number(a.rpm) + " r/min", "main-shaft angle (deg)", "N m, N / 100", {}, {}};
  chart.series = {{"balancing torque (N m)", {}}, {"pin O (N/100)", {}}, {"pin C (N/100)", {}}};
  for (const NeedleForces& f : sw) {
    const double th = deg(f.state.theta1_rad);
    put(out, th);
    put(out, f.balancing_torque_nm);
    put(out, f.pin_o_n.norm());
    put(out, f.pin_a_n.norm());
    put(out, f.pin_b_n.norm());
    put(out, f.pin_c_n().norm());
    put(out, f.pin_d_n.norm());
    put(out, f.pin_e_n.norm());
    put(out, f.guide_n);
    put(out, f.weld_torque_nm);
    put(out, f.friction_n, true);
    chart.x.push_back(th);
    chart.series[0].y.push_back(f.balancing_torque_nm);
    chart.series[1].y.push_back(f.pin_o_n.norm() / 100.0);
    chart.series[2].y.push_back(f.pin_c_n().norm() / 100.0);
  }
  if (!a.svg.empty() && !write_svg(chart, a.svg)) throw UsageError("--svg: cannot write '" + a.svg + "'");
  emit(out);
}

}  // namespace loom::dyncli
