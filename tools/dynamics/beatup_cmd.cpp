// loom-dynamics beatup: a beat-up over one crank turn — beater acceleration and force, crank torque
// and pin loads — at a constant crank speed or under the elliptic-gear crank law; or, with
// --target-force-n, the crank speed whose in-warp peak beat force is the target. The linkage is the
// thesis' (Table 5.1) unless --config or explicit lengths and masses describe the builder's own.
// Rows are streamed (constant memory at any --samples); the SVG, when asked for, holds its points.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "commands.hpp"
#include "linkage_options.hpp"
#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/design/dynamics_batten.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/dynamics_body.hpp"
#include "svg_plot.hpp"

namespace loom::dyncli {

using namespace loom::motion;

CLI::App* add_beatup(CLI::App& app, BeatupArgs& a) {
  CLI::App* c = app.add_subcommand("beatup", "Beat-up four-bar inverse dynamics over one crank turn (CSV)");
  CLI::Option* speed =
      c->add_option("--crank-rad-s", a.crank_rad_s, "Crank speed (rad/s; the mean speed under --cam-e)")
          ->check(cli::positive_number());
  CLI::Option* target =
      c->add_option("--target-force-n", a.target_force_n,
                    "Print the constant crank speed whose peak beat force (in the warp) is this")
          ->check(cli::positive_number());
  speed->excludes(target);
  c->add_option("--samples", a.samples, "Samples over one crank turn")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  c->add_option("--contact-n", a.contact_n,
                "Cloth resistance on the beater while it advances through the warp (N)")
      ->check(cli::non_negative_number())
      ->capture_default_str();
  c->add_option("--gravity-deg", a.gravity_deg, "Direction of gravity in the linkage frame (A0->B0 is 0 deg)")
      ->check(cli::finite_number())
      ->capture_default_str();
  c->add_option("--cam-e", a.cam_e,
                "Drive the crank by the elliptic-gear law of this eccentricity (004; 0 = constant)")
      ->check(cli::eccentricity())
      ->capture_default_str()
      ->excludes(target);
  c->add_option("--cam-phi02-rad", a.cam_phi02_rad, "Crank orientation on the driven pinion for --cam-e")
      ->check(cli::finite_number())
      ->capture_default_str()
      ->excludes(target);
  c->add_option("--svg", a.svg,
                "Also plot beater force, crank torque and pin loads vs crank angle to this SVG file")
      ->excludes(target);
  c->add_flag(
      "--extra", a.extra,
      "Append "
      "crank_rad_s,in_warp,contact_force_n,transmission_deg,near_toggle,shaking_force_n,shaking_moment_nm");
  add_linkage_options(c, a.linkage);
  return c;
}

namespace {

BeatUpDynamics make_dynamics(const BeatupArgs& a, const Linkage& l) {
  BeatUpDynamics::Options o;
  o.gravity_m_s2 =
      kStandardGravity_m_s2 * Eigen::Vector2d(std::cos(rad(a.gravity_deg)), std::sin(rad(a.gravity_deg)));
  return BeatUpDynamics(l.geometry, l.masses, o);
}

void run_target(const BeatUpDynamics& d, double target_n) {
  const double w = d.crank_speed_for_beat_force(target_n);
  const BeatForcePeak p = d.peak_beat_force(w);
  cli::CsvWriter out("target_force_n,crank_rad_s,crank_rpm,peak_crank_deg,fell_force_n");
  out.num(target_n).num(w).num(w * 60.0 / kTwoPi).num(deg(p.crank_rad)).num(p.fell_force_n);
  out.end_row();
  out.finish();
}

}  // namespace

void run_beatup(const CLI::App& cmd, const BeatupArgs& a) {
  const Linkage l = make_linkage(cmd, a.linkage);
  const BeatUpDynamics d = make_dynamics(a, l);
  const bool have_speed = cmd.count("--crank-rad-s") > 0, have_target = cmd.count("--target-force-n") > 0;
  if (have_target) return run_target(d, a.target_force_n);
  double speed = a.crank_rad_s;
  if (!have_speed) {
    // A config names the loom's crank speed or its beat-force target; use it when no option does.
    if (l.config_crank_speed_rad_s) {
      speed = *l.config_crank_speed_rad_s;
    } else if (l.config_beat_force_target_n && a.cam_e == 0.0 && a.svg.empty()) {
      return run_target(d, *l.config_beat_force_target_n);
    } else {
      throw UsageError("beatup: give --crank-rad-s W (forces over a turn) or --target-force-n F");
    }
  }
  const EllipticGearPair gear(kBatten004GearA_m, a.cam_e, 2);
  if (gear.near_degenerate()) {
    std::fprintf(
        stderr,
        "loom-dynamics: warning: extreme ratio: --cam-e %.17g is near 1: the crank speed swings by %.3g:1 "
        "and forces by its square; the results are finite but ill-conditioned\n",
        a.cam_e, gear.max_speed_ratio() * gear.max_speed_ratio());
  }
  const BeatContact contact{a.contact_n};
  std::string header =
      "crank_deg,tip_acc_m_s2,beater_force_n,crank_torque_nm,pin_a0_n,pin_a_n,pin_b_n,pin_b0_n";
  if (a.extra)
    header +=
        ",crank_rad_s,in_warp,contact_force_n,transmission_deg,near_toggle,shaking_force_n,shaking_moment_nm";
  cli::CsvWriter out(header);
  const bool plot = !a.svg.empty();
  Chart chart{"Beat-up at " + cli::format_number(speed) + " rad/s", "crank angle (deg)", "N, N m", {}, {}};
  chart.series = {
      {"beater force (N)", {}}, {"crank torque (N m)", {}}, {"pin A0 (N)", {}}, {"pin B0 (N)", {}}};
  long near_toggle = 0;
  for (int i = 0; i < a.samples; ++i) {
    const double phi1 = kTwoPi * i / a.samples;
    // Under the cam the driving angle advances uniformly; the crank follows the gear law.
    const CrankMotion c = a.cam_e > 0.0 ? elliptic_gear_crank(gear, a.cam_phi02_rad, phi1, speed)
                                        : CrankMotion{phi1, speed, 0.0};
    const BeatUpSample s = d.inverse(c, contact);
    near_toggle += s.near_toggle ? 1 : 0;
    out.num(deg(wrap_two_pi(c.theta_rad)))
        .num(s.tip_acc_abs_m_s2)
        .num(s.beater_force_n)
        .num(s.forces.crank_torque_nm);
    out.num(s.forces.pin_a0_n.norm())
        .num(s.forces.pin_a_n.norm())
        .num(s.forces.pin_b_n.norm())
        .num(s.forces.pin_b0_n.norm());
    if (a.extra) {
      const std::array<BodyMotion, 3> mo = d.motion(c);
      const ShakingLoad sh = shaking_load(d.bodies(), mo, Eigen::Vector2d::Zero());
      out.num(c.omega_rad_s)
          .num(s.in_warp ? 1.0 : 0.0)
          .num(s.contact_force_n.norm())
          .num(deg(s.transmission_rad));
      out.num(s.near_toggle ? 1.0 : 0.0).num(sh.force_n.norm()).num(sh.moment_nm);
    }
    out.end_row();
    if (plot) {
      chart.x.push_back(deg(c.theta_rad));  // unwrapped: under the cam the crank angle starts at φ02
      chart.series[0].y.push_back(s.beater_force_n);
      chart.series[1].y.push_back(s.forces.crank_torque_nm);
      chart.series[2].y.push_back(s.forces.pin_a0_n.norm());
      chart.series[3].y.push_back(s.forces.pin_b0_n.norm());
    }
  }
  if (plot && !write_svg(chart, a.svg)) throw UsageError("--svg: cannot write '" + a.svg + "'");
  out.finish();
  if (near_toggle > 0) {
    std::fprintf(
        stderr,
        "loom-dynamics: warning: %ld of %d samples are within %.1f deg of a toggle; pin forces there "
        "are large\n",
        near_toggle, a.samples, deg(d.options().near_toggle_rad));
  }
}

}  // namespace loom::dyncli
