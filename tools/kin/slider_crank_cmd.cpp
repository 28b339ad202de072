// `loom-kin slider-crank`: an offset slider-crank (crank pivot at the origin, slider line y = offset)
// swept over one crank turn at --omega/--alpha, or summarised in one row. Geometric refusals name
// the length options they come from.
#include "slider_crank_cmd.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/slider_crank.hpp"

namespace loom::kin {

using cli::eccentricity;
using cli::finite_number;
using cli::positive_number;

CLI::App* add_slider_crank_command(CLI::App& app, SliderCrankArgs& a) {
  CLI::App* c = app.add_subcommand(
      "slider-crank",
      "Offset slider-crank over one crank turn: slider and coupler motion, transmission angle");
  c->add_option("--crank", a.crank, "Crank a (any one length unit)")->check(positive_number())->required();
  c->add_option("--coupler", a.coupler, "Coupler b")->check(positive_number())->required();
  c->add_option("--offset", a.offset, "Slider line's signed distance e from the crank pivot")
      ->check(finite_number())
      ->capture_default_str();
  c->add_option("--samples", a.samples, "Samples over one crank turn")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  c->add_option("--omega", a.omega, "Crank speed, rad/s")->check(finite_number())->capture_default_str();
  c->add_option("--alpha", a.alpha, "Crank acceleration, rad/s^2")
      ->check(finite_number())
      ->capture_default_str();
  c->add_flag("--summary", a.summary, "One row: dead centres, stroke, crank rotations, time ratio, mu_min");
  return c;
}

namespace {

// The same warning as loom-kin fourbar's: a transmission angle this close to 0 amplifies rates and
// length errors by 1/sin μ (μ_min = acos((a + |e|)/b) for the slider-crank).
void warn_near_toggle(const loom::motion::SliderCrank& m) {
  using namespace loom::motion;
  const double mu_min = slider_dead_centres(m).mu_min_rad;
  if (std::sin(mu_min) < kNearToggleSine) {
    std::fprintf(
        stderr,
        "loom-kin: warning: near toggle: the transmission angle reaches %.6g deg (|sin mu| = %.3g < %g); "
        "rates there are amplified by 1/|sin mu| and small length errors move the linkage a long way\n",
        deg(mu_min), std::sin(mu_min), kNearToggleSine);
  }
}

}  // namespace

void run_slider_crank(const SliderCrankArgs& a) {
  using namespace loom::motion;
  const SliderCrank m{a.crank, a.coupler, a.offset};
  try {
    warn_near_toggle(m);
    if (a.summary) {
      const SliderDeadCentres dc = slider_dead_centres(m);
      cli::CsvWriter out(
          "theta_extended_deg,theta_folded_deg,x_extended,x_folded,stroke,phi_extend_to_fold_deg,"
          "phi_fold_to_extend_deg,time_ratio,mu_min_deg");
      for (double v : {deg(dc.theta_extended_rad), deg(dc.theta_folded_rad), dc.x_extended, dc.x_folded,
                       dc.stroke, deg(dc.phi_extend_to_fold_rad), deg(dc.phi_fold_to_extend_rad),
                       dc.time_ratio, deg(dc.mu_min_rad)}) {
        out.num(v);
      }
      out.end_row();
      out.finish();
    } else {
      validate_slider_crank(m);
      cli::CsvWriter out(
          "theta_deg,x,x_dot,x_ddot,coupler_deg,coupler_rate_rad_s,coupler_accel_rad_s2,transmission_deg");
      for (int i = 0; i < a.samples; ++i) {
        const double theta_deg = 360.0 * static_cast<double>(i) / static_cast<double>(a.samples);
        const SliderState s = slider_state(m, rad(theta_deg), a.omega, a.alpha);
        for (double v : {theta_deg, s.x, s.x_dot, s.x_ddot, deg(s.coupler_angle_rad), s.coupler_rate_rad_s,
                         s.coupler_accel_rad_s2, deg(s.transmission_rad)}) {
          out.num(v);
        }
        out.end_row();
      }
      out.finish();
    }
  } catch (const MotionError& e) {
    throw MotionError(e.code(), std::string("--crank/--coupler/--offset: ") + e.what());
  }
}

}  // namespace loom::kin
