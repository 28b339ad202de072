// loom-dynamics beatup: the default (thesis Table 5.1) beat-up over one crank turn — beater
// acceleration and force, crank torque and pin loads — at a constant crank speed or under the
// elliptic-gear crank law; or, with --target-force-n, the crank speed whose in-warp peak beat force
// is the target.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "checks.hpp"
#include "commands.hpp"
#include "csv.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/dynamics_batten.hpp"
#include "loom/motion/dynamics_body.hpp"
#include "svg_plot.hpp"

namespace loom::dyncli {

using namespace loom::motion;

CLI::App* add_beatup(CLI::App& app, BeatupArgs& a) {
  CLI::App* c = app.add_subcommand("beatup", "Beat-up four-bar inverse dynamics over one crank turn (CSV)");
  CLI::Option* speed = c->add_option("--crank-rad-s", a.crank_rad_s, "Crank speed (rad/s; the mean speed under --cam-e)")
                           ->check(positive_number());
  CLI::Option* target = c->add_option("--target-force-n", a.target_force_n,
                                      "Print the constant crank speed whose peak beat force (in the warp) is this")
                            ->check(positive_number());
  speed->excludes(target);
  c->add_option("--samples", a.samples, "Samples over one crank turn")->check(CLI::Range(1, 10000000))->capture_default_str();
  c->add_option("--beater-kg", a.beater_kg, "Beater mass at the beater arm")->check(non_negative_number())->capture_default_str();
  c->add_option("--contact-n", a.contact_n, "Cloth resistance on the beater while it advances through the warp (N)")
      ->check(non_negative_number())->capture_default_str();
  c->add_option("--gravity-deg", a.gravity_deg, "Direction of gravity in the linkage frame (A0->B0 is 0 deg)")
      ->check(finite_number())->capture_default_str();
  c->add_option("--cam-e", a.cam_e, "Drive the crank by the elliptic-gear law of this eccentricity (004; 0 = constant)")
      ->check(eccentricity())->capture_default_str()->excludes(target);
  c->add_option("--cam-phi02-rad", a.cam_phi02_rad, "Crank orientation on the driven pinion for --cam-e")
      ->check(finite_number())->capture_default_str()->excludes(target);
  c->add_option("--svg", a.svg, "Also plot beater force, crank torque and pin loads vs crank angle to this SVG file")
      ->excludes(target);
  c->add_flag("--extra", a.extra,
              "Append crank_rad_s,in_warp,contact_force_n,transmission_deg,near_toggle,shaking_force_n,shaking_moment_nm");
  return c;
}

namespace {

BeatUpDynamics make_dynamics(const BeatupArgs& a) {
  const BeatUpGeometry g = default_beatup_geometry();
  BeatUpDynamics::Options o;
  o.gravity_m_s2 = kStandardGravity_m_s2 * Eigen::Vector2d(std::cos(rad(a.gravity_deg)), std::sin(rad(a.gravity_deg)));
  return BeatUpDynamics(g, beatup_masses(g, a.beater_kg), o);
}

void run_target(const BeatupArgs& a) {
  const BeatUpDynamics d = make_dynamics(a);
  const double w = d.crank_speed_for_beat_force(a.target_force_n);
  const BeatForcePeak p = d.peak_beat_force(w);
  std::string out = "target_force_n,crank_rad_s,crank_rpm,peak_crank_deg,fell_force_n\n";
  put(out, a.target_force_n);
  put(out, w);
  put(out, w * 60.0 / kTwoPi);
  put(out, deg(p.crank_rad));
  put(out, p.fell_force_n, true);
  emit(out);
}

}  // namespace

void run_beatup(const CLI::App& cmd, const BeatupArgs& a) {
  const bool have_speed = cmd.count("--crank-rad-s") > 0, have_target = cmd.count("--target-force-n") > 0;
  if (have_target) {
    run_target(a);
    return;
  }
  if (!have_speed) throw UsageError("beatup: give --crank-rad-s W (forces over a turn) or --target-force-n F");
  const BeatUpDynamics d = make_dynamics(a);
  const EllipticGearPair gear(kBatten004GearA_m, a.cam_e, 2);
  const BeatContact contact{a.contact_n};
  std::string out = "crank_deg,tip_acc_m_s2,beater_force_n,crank_torque_nm,pin_a0_n,pin_a_n,pin_b_n,pin_b0_n";
  out += a.extra ? ",crank_rad_s,in_warp,contact_force_n,transmission_deg,near_toggle,shaking_force_n,shaking_moment_nm\n"
                 : "\n";
  Chart chart{"Beat-up at " + format_number(a.crank_rad_s) + " rad/s", "crank angle (deg)", "N, N m", {}, {}};
  chart.series = {{"beater force (N)", {}}, {"crank torque (N m)", {}}, {"pin A0 (N)", {}}, {"pin B0 (N)", {}}};
  int near_toggle = 0;
  for (int i = 0; i < a.samples; ++i) {
    const double phi1 = kTwoPi * i / a.samples;
    // Under the cam the driving angle advances uniformly; the crank follows the gear law.
    const CrankMotion c = a.cam_e > 0.0 ? elliptic_gear_crank(gear, a.cam_phi02_rad, phi1, a.crank_rad_s)
                                        : CrankMotion{phi1, a.crank_rad_s, 0.0};
    const BeatUpSample s = d.inverse(c, contact);
    near_toggle += s.near_toggle ? 1 : 0;
    const double crank_deg = deg(wrap_two_pi(c.theta_rad));
    put(out, crank_deg);
    put(out, s.tip_acc_abs_m_s2);
    put(out, s.beater_force_n);
    put(out, s.forces.crank_torque_nm);
    put(out, s.forces.pin_a0_n.norm());
    put(out, s.forces.pin_a_n.norm());
    put(out, s.forces.pin_b_n.norm());
    put(out, s.forces.pin_b0_n.norm(), !a.extra);
    if (a.extra) {
      const std::array<BodyMotion, 3> mo = d.motion(c);
      const ShakingLoad sh = shaking_load(d.bodies(), mo, Eigen::Vector2d::Zero());
      put(out, c.omega_rad_s);
      put(out, s.in_warp ? 1.0 : 0.0);
      put(out, s.contact_force_n.norm());
      put(out, deg(s.transmission_rad));
      put(out, s.near_toggle ? 1.0 : 0.0);
      put(out, sh.force_n.norm());
      put(out, sh.moment_nm, true);
    }
    chart.x.push_back(deg(c.theta_rad));  // unwrapped: under the cam the crank angle starts at φ02
    chart.series[0].y.push_back(s.beater_force_n);
    chart.series[1].y.push_back(s.forces.crank_torque_nm);
    chart.series[2].y.push_back(s.forces.pin_a0_n.norm());
    chart.series[3].y.push_back(s.forces.pin_b0_n.norm());
  }
  if (!a.svg.empty()) {
    if (!write_svg(chart, a.svg)) throw UsageError("--svg: cannot write '" + a.svg + "'");
  }
  emit(out);
  if (near_toggle > 0) {
    std::fprintf(stderr,
                 "loom-dynamics: warning: %d of %d samples are within %.1f deg of a toggle; pin forces there "
                 "are large\n",
                 near_toggle, a.samples, deg(d.options().near_toggle_rad));
  }
}

}  // namespace loom::dyncli
