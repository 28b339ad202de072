// The loom-synth subcommands as plain functions: parsed arguments in, CSV on `out`, notes on `err`.
// Bad input throws ArgError naming the argument and its value; main() turns it into exit code 2.
#pragma once

#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "loom/cli/run.hpp"
#include "loom/cli/table_format.hpp"
#include "loom/motion/design/synthesis.hpp"
#include "loom/motion/design/three_point.hpp"
#include "loom/motion/errors.hpp"

namespace loom::synth {

using cli::CsvFormat;
using cli::input_value;
using cli::write_row;

// A bad argument or combination, naming it; main() reports it with exit status 2.
class ArgError : public cli::UsageError {
 public:
  using cli::UsageError::UsageError;
};

// configure-time only. Runs f(); a MotionError it throws becomes an ArgError blaming `arg`
// (e.g. "--beta 80").
template <class F>
auto blame(const std::string& arg, F&& f) -> decltype(f()) {
  try {
    return std::forward<F>(f)();
  } catch (const motion::MotionError& e) {
    throw ArgError(arg + ": " + e.what());
  }
}

// φ from --phi as typed: its supplement 180 − φ exact in decimal when the text is plain decimal (hard
// case A2: "179.999999999999" is 1e-12° from 180°, not the double nearest it), else from the double.
inline motion::CrankRotation crank_rotation(double phi_deg, const std::string& phi_text) {
  return motion::CrankRotation::decimal_degrees(phi_text).value_or(motion::CrankRotation::degrees(phi_deg));
}

struct SliderCrankArgs {
  double phi_deg = 0.0;
  std::string phi_text;  // --phi as typed (crank_rotation)
  bool has_phi = false;
  std::string phi_range;  // "first:last[:step]" in degrees
  double stroke = 1.0;
  double lambda = 0.0;
  bool has_lambda = false;
  bool full_precision = false;
};
// configure-time only (offline tool). phi_deg,a,b,c,mu_min_deg,lambda — one row per φ.
void run_slider_crank(const SliderCrankArgs& args, std::ostream& out, std::ostream& err);

struct CrankRockerArgs {
  double psi_deg = 0.0;
  double phi_deg = 0.0;
  std::string phi_text;  // --phi as typed (crank_rotation)
  double beta_deg = 0.0;
  bool has_beta = false;
  double ground = 1.0;
  bool full_precision = false;
};
// configure-time only (offline tool). beta_deg,a,b,c,mu_min_deg — one row per integer β from the
// upper to the lower bound, or one for --beta.
void run_crank_rocker(const CrankRockerArgs& args, std::ostream& out, std::ostream& err);

struct DesignArgs {
  double stroke = 0.0;
  bool has_stroke = false;
  double swing_deg = 0.0;
  bool has_swing = false;
  double phi_deg = 0.0;
  std::string phi_text;  // --phi as typed (crank_rotation)
  double lambda = 0.0;
  bool has_lambda = false;
  double beta_deg = 0.0;
  bool has_beta = false;
  double ground = 1.0;
  bool thesis_rounding = false;
  bool full_precision = false;
};
// configure-time only (offline tool). One beat-up linkage: slider-crank from --stroke, crank-rocker
// from --swing; one CSV row with link lengths, μ_min, Grashof class and dead centres.
void run_design(const DesignArgs& args, std::ostream& out, std::ostream& err);

// configure-time only. Throws ArgError unless v is a finite length > 0.
void require_positive_length(const char* name, double v);

// configure-time only. The stderr note for a Khare–Dave design flagged kDesignNearSpecialCase.
void note_near_special_case(std::ostream& err, double psi_deg, double phi_deg);

struct ThreePointArgs {
  double theta0_deg = 0.0;
  std::vector<std::string> points;  // "RX,RY,THETA2": mm, mm, degrees
  bool full_precision = false;
};
// configure-time only (offline tool). Seed 001's three-precision-point synthesis:
// lambda,a0,a1,a2,theta1_1_deg,theta1_2_deg,theta1_3_deg,closure_residual — one row per real solution.
void run_three_point(const ThreePointArgs& args, std::ostream& out, std::ostream& err);

// configure-time only. "RX,RY,THETA2" (mm, mm, degrees) → a precision point in mm and radians;
// throws ArgError naming `--point <text>` (index: the point's 0-based position, for the message).
motion::PrecisionPoint parse_precision_point(const std::string& text, int index);

struct KnotterArgs {
  double theta0_deg = 275.0;
  std::vector<std::string> points{"0,0,10", "25,15,3", "30,1,-25"};  // seed 001's (mm, mm, deg)
  double warp_entry_mm = 20.0;
  double min_transmission_deg = 30.0;
  std::string drive = "auto";  // "auto", "first", "second": which chain's side link the servo drives
  // The servo at its output for the cycle-time comment (defaults: loom::motion::seed001_knot_cycle_spec()):
  // a speed cap, the torque-speed line's no-load speed and its peak torque.
  double max_speed_rad_s = 0.0, no_load_speed_rad_s = 0.0, max_torque_nm = 0.0;
};
// configure-time only (offline tool). The knotting four-bar from the two three-point chains, checked
// (branch, order, transmission, toggle) by the knot cycle, as [knotting.linkage] config lines.
void run_knotter(const KnotterArgs& args, std::ostream& out, std::ostream& err);

}  // namespace loom::synth
