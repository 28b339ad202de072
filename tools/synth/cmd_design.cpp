// `loom-synth design`: one beat-up linkage from the loom builder's numbers — a Söylemez slider-crank
// from (stroke, φ) or a Khare–Dave crank-rocker from (swing ψ, φ) — with link lengths, μ_min,
// Grashof class and dead centres in one CSV row. --thesis-rounding reproduces Table 4.3's digits.
#include <cmath>
#include <sstream>

#include "commands.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/slider_crank.hpp"

namespace loom::synth {

namespace {

using motion::deg;
using motion::rad;

// The thesis computed Table 4.3 as 12 × (Table 4.2 rounded to 6 decimals); this does the same.
double thesis_scaled(double unit_length, double stroke) {
  return stroke * std::round(unit_length * 1e6) / 1e6;
}

void design_slider_crank(const DesignArgs& args, std::ostream& out, std::ostream& err) {
  require_positive_length("--stroke", args.stroke);
  const motion::CrankRotation phi = crank_rotation(args.phi_deg, args.phi_text);  // π − φ exact near 180°
  blame("--phi " + input_value(args.phi_deg), [&] { return motion::soylemez_lambda_bounds(phi); });
  const double stroke = args.thesis_rounding ? 1.0 : args.stroke;
  motion::SliderCrankDesign d =
      args.has_lambda ? blame("--lambda " + input_value(args.lambda),
                              [&] { return motion::soylemez_slider_crank(stroke, phi, args.lambda); })
                      : motion::soylemez_slider_crank(stroke, phi);
  if (args.thesis_rounding) {
    d.mechanism.crank = thesis_scaled(d.mechanism.crank, args.stroke);
    d.mechanism.coupler = thesis_scaled(d.mechanism.coupler, args.stroke);
    d.mechanism.offset = thesis_scaled(d.mechanism.offset, args.stroke);
    d.stroke = args.stroke;
  }
  const motion::SliderDeadCentres dc = motion::slider_dead_centres(d.mechanism);
  const bool change_point = (d.flags & motion::kDesignChangePoint) != 0;

  const CsvFormat f(args.full_precision);
  // The row is formatted before anything is printed: a value that is not finite prints nothing.
  std::ostringstream row;
  write_row(row, {"slider-crank", f.input(args.phi_deg), f.length(dc.stroke), f.length(d.mechanism.crank),
                  f.length(d.mechanism.coupler), f.length(d.mechanism.offset), f.ratio(d.lambda),
                  f.angle_deg(deg(d.mu_min_rad)), change_point ? "change-point" : "crank-slider",
                  f.angle_deg(deg(dc.theta_extended_rad)), f.angle_deg(deg(dc.theta_folded_rad)),
                  f.length(dc.x_extended), f.length(dc.x_folded)});
  out << "mechanism,phi_deg,stroke,a,b,c,lambda,mu_min_deg,grashof,crank_extended_deg,"
         "crank_folded_deg,slider_extended,slider_folded\n"
      << row.str();
  if (change_point) {
    err << "loom-synth: note: change-point slider-crank (b = a + c): mu_min = 0, not a usable "
           "beat-up\n";
  }
}

const char* grashof_name(const motion::CrankRockerDesign& d) {
  if (d.flags & motion::kDesignChangePoint) return "change-point";
  return motion::grashof_class_name(
      motion::classify(motion::FourBar{d.ground, d.crank, d.coupler, d.rocker}));
}

void design_crank_rocker(const DesignArgs& args, std::ostream& out, std::ostream& err) {
  require_positive_length("--ground", args.ground);
  if (args.has_beta && args.has_lambda) throw ArgError("--beta / --lambda: give at most one of them");
  const double psi = rad(args.swing_deg);
  const motion::CrankRotation phi = crank_rotation(args.phi_deg, args.phi_text);
  blame("--swing " + input_value(args.swing_deg) + " --phi " + input_value(args.phi_deg),
        [&] { return motion::khare_dave_beta_bounds(psi, phi); });
  motion::CrankRockerDesign d;
  if (args.has_beta) {
    d = blame("--beta " + input_value(args.beta_deg),
              [&] { return motion::khare_dave_crank_rocker(psi, phi, rad(args.beta_deg), args.ground); });
  } else if (args.has_lambda) {
    d = blame("--lambda " + input_value(args.lambda),
              [&] { return motion::khare_dave_for_ratio(psi, phi, args.lambda, args.ground); });
  } else {
    d = blame("--phi " + input_value(args.phi_deg) + " (give --beta or --lambda)",
              [&] { return motion::khare_dave_best_beta(psi, phi, args.ground); });
  }

  const CsvFormat f(args.full_precision);
  const double lambda = d.coupler > 0.0 ? d.crank / d.coupler : 0.0;
  std::ostringstream row;
  write_row(row, {"crank-rocker", f.input(args.swing_deg), f.input(args.phi_deg),
                  f.angle_deg(deg(d.beta_rad)), f.length(d.crank), f.length(d.coupler), f.length(d.rocker),
                  f.length(d.ground), f.ratio(lambda), f.angle_deg(deg(d.mu_min_rad)), grashof_name(d),
                  f.angle_deg(deg(d.crank_extended_rad)), f.angle_deg(deg(d.crank_folded_rad)),
                  f.angle_deg(deg(d.rocker_extended_rad)), f.angle_deg(deg(d.rocker_folded_rad))});
  out << "mechanism,psi_deg,phi_deg,beta_deg,a,b,c,d,lambda,mu_min_deg,grashof,crank_extended_deg,"
         "crank_folded_deg,rocker_extended_deg,rocker_folded_deg\n"
      << row.str();
  if (d.flags & motion::kDesignChangePoint) {
    err << "loom-synth: note: beta at a bound: degenerate linkage, mu_min = 0, not a usable "
           "beat-up\n";
  }
  if (d.flags & motion::kDesignNearSpecialCase) note_near_special_case(err, args.swing_deg, args.phi_deg);
}

}  // namespace

void run_design(const DesignArgs& args, std::ostream& out, std::ostream& err) {
  if (args.has_stroke == args.has_swing) {
    throw ArgError("--stroke / --swing: give exactly one (stroke: slider-crank, swing: crank-rocker)");
  }
  if (args.has_stroke) {
    if (args.has_beta) throw ArgError("--beta: only for a crank-rocker (--swing)");
    design_slider_crank(args, out, err);
  } else {
    if (args.thesis_rounding) throw ArgError("--thesis-rounding: only for a slider-crank (--stroke)");
    design_crank_rocker(args, out, err);
  }
}

}  // namespace loom::synth
