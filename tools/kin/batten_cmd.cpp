// loom-kin's batten subcommands: options in SI as 004 prints them, one shared option set for the
// geometry and the gear, the drive evaluated in closed form (or by Newton with --solver newton).
#include "batten_cmd.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/batten.hpp"

namespace loom::kin {

using cli::eccentricity;
using cli::finite_number;
using cli::positive_number;

namespace {

void add_common(CLI::App* c, BattenArgs& a) {
  c->add_option("--e", a.e, "Eccentricity of the elliptic pitch curves, [0, 1)")
      ->check(eccentricity())
      ->capture_default_str();
  c->add_option("--k", a.k, "Lobes of the pitch curves (004: 2)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  c->add_option("--a-m", a.a_m, "Half the gear centre distance")
      ->check(positive_number())
      ->capture_default_str();
  c->add_option("--omega1", a.omega1_rad_s, "Driving-pinion speed, rad/s")
      ->check(positive_number())
      ->capture_default_str();
  static const char* const names[9] = {"--l1-m", "--l2-m", "--l3-m", "--l4-m", "--l5-m",
                                       "--l6-m", "--l7-m", "--l8-m", "--l9-m"};
  static const char* const help[9] = {"Crank L1",          "Coupler L2",       "First rocker L3",
                                      "Second coupler L4", "Batten L5",        "Ground offset L6",
                                      "Ground offset L7",  "Ground offset L8", "Ground offset L9"};
  for (int i = 0; i < 9; ++i) {
    c->add_option(names[i], a.l_m[i], help[i])
        ->check(i < 5 ? positive_number() : finite_number())
        ->capture_default_str();
  }
  c->add_option("--loop1", a.loop1, "Side of B relative to A->O3 (004's double swing: right)")
      ->check(CLI::IsMember({"right", "left"}))
      ->capture_default_str();
  c->add_option("--loop2", a.loop2, "Side of D relative to B->P (004's double swing: right)")
      ->check(CLI::IsMember({"right", "left"}))
      ->capture_default_str();
  c->add_option("--samples", a.samples, "Samples over one driving-pinion turn")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
}

loom::motion::BattenDrive make_drive(const BattenArgs& a, double phi02) {
  using namespace loom::motion;
  const BattenDims d{a.l_m[0], a.l_m[1], a.l_m[2], a.l_m[3], a.l_m[4],
                     a.l_m[5], a.l_m[6], a.l_m[7], a.l_m[8]};
  BattenBranch b;
  b.loop1 = a.loop1 == "left" ? LoopSide::kLeft : LoopSide::kRight;
  b.loop2 = a.loop2 == "left" ? LoopSide::kLeft : LoopSide::kRight;
  return BattenDrive(EllipticGearPair(a.a_m, a.e, a.k), BattenLinkage(d, b), phi02);
}

void warn_about_gear(const loom::motion::EllipticGearPair& g) {
  if (g.near_degenerate()) {
    std::fprintf(stderr,
                 "loom-kin: warning: extreme ratio: --e %.17g is near 1: the crank acceleration swings by "
                 "%.3g:1, results "
                 "are finite but ill-conditioned\n",
                 g.eccentricity(), g.max_speed_ratio() * g.max_speed_ratio());
  }
  if (g.concave_pitch_curve()) {
    std::fprintf(stderr,
                 "loom-kin: warning: --e %.6g > 1/(k^2-1) = %.6g: the pitch curve has concave "
                 "stretches and cannot be cut as a gear\n",
                 g.eccentricity(), 1.0 / (g.lobes() * g.lobes() - 1.0));
  }
}

}  // namespace

CLI::App* add_batten_command(CLI::App& app, BattenArgs& a) {
  CLI::App* c = app.add_subcommand("batten", "Elliptic-gear batten drive (004) over one driving-pinion turn");
  add_common(c, a);
  c->add_option("--phi02-rad", a.phi02_rad, "Crank angle on the driven pinion (004 eqn 8)")
      ->check(finite_number())
      ->capture_default_str();
  c->add_option("--solver", a.solver, "Position solver")
      ->check(CLI::IsMember({"closed", "newton"}))
      ->capture_default_str();
  c->add_option("--newton-tol", a.newton_tol, "Newton tolerance on |F|, relative to the largest link")
      ->check(cli::finite_range(1e-15, 1e-2))
      ->capture_default_str();
  c->add_flag("--pose", a.pose, "Append gamma2_rad,gamma3_rad,gamma4_rad");
  return c;
}

CLI::App* add_batten_phase_command(CLI::App& app, BattenArgs& a) {
  CLI::App* c = app.add_subcommand(
      "batten-phase",
      "Scan the crank phase phi02: batten acceleration at its turning points and gain over e = 0");
  add_common(c, a);
  c->add_option("--step-deg", a.step_deg, "phi02 step over [0, 360)")
      ->check(cli::finite_range(0.01, 90.0))
      ->capture_default_str();
  return c;
}

void run_batten(const BattenArgs& a) {
  using namespace loom::motion;
  const BattenDrive drive = make_drive(a, a.phi02_rad);
  warn_about_gear(drive.gear());
  const BattenSolver solver = a.solver == "newton" ? BattenSolver::kNewton : BattenSolver::kClosedForm;
  cli::CsvWriter out(std::string("phi1_rad,phi2_rad,psi_rad,psi_dot_rad_s,psi_ddot_rad_s2") +
                     (a.pose ? ",gamma2_rad,gamma3_rad,gamma4_rad" : ""));
  batten_sweep(
      drive, a.samples, a.omega1_rad_s,
      [&](const BattenSample& s) {
        out.num(s.phi1_rad).num(s.phi2_rad).num(s.psi_rad).num(s.psi_dot_rad_s).num(s.psi_ddot_rad_s2);
        if (a.pose) out.num(s.pose.gamma2_rad).num(s.pose.gamma3_rad).num(s.pose.gamma4_rad);
        out.end_row();
      },
      solver, NewtonOptions{a.newton_tol, 50});
  out.finish();
}

namespace {

struct PhaseMetrics {
  double peak;    // max |ψ''| over the turn (samples)
  double at_max;  // max |ψ''| at the turning points where ψ is a local maximum
  double at_min;  // ... where ψ is a local minimum
};

PhaseMetrics metrics(const loom::motion::BattenDrive& d, int samples, double omega1) {
  using namespace loom::motion;
  PhaseMetrics m{0.0, 0.0, 0.0};
  batten_sweep(d, samples, omega1,
               [&](const BattenSample& s) { m.peak = std::max(m.peak, std::abs(s.psi_ddot_rad_s2)); });
  for (const BattenExtreme& x : batten_extremes(d, samples, omega1)) {
    double& slot = x.maximum ? m.at_max : m.at_min;
    slot = std::max(slot, std::abs(x.psi_ddot_rad_s2));
  }
  return m;
}

}  // namespace

void run_batten_phase(const BattenArgs& a) {
  using namespace loom::motion;
  warn_about_gear(EllipticGearPair(a.a_m, a.e, a.k));
  BattenArgs circular = a;
  circular.e = 0.0;
  // With e = 0 the crank turns uniformly and φ02 only shifts the curves: one reference serves all.
  const PhaseMetrics ref = metrics(make_drive(circular, 0.0), a.samples, a.omega1_rad_s);
  cli::CsvWriter out(
      "phi02_deg,psi_ddot_peak_rad_s2,psi_ddot_at_psi_max_rad_s2,psi_ddot_at_psi_min_rad_s2,"
      "gain_peak,gain_at_psi_max,gain_at_psi_min");
  const int steps = static_cast<int>(std::floor(360.0 / a.step_deg + 1e-9));
  for (int i = 0; i < steps; ++i) {
    const double phi02_deg = a.step_deg * i;
    const PhaseMetrics m = metrics(make_drive(a, rad(phi02_deg)), a.samples, a.omega1_rad_s);
    out.num(phi02_deg).num(m.peak).num(m.at_max).num(m.at_min).num(m.peak / ref.peak);
    out.num(ref.at_max > 0.0 ? m.at_max / ref.at_max : 0.0)
        .num(ref.at_min > 0.0 ? m.at_min / ref.at_min : 0.0);
    out.end_row();
  }
  out.finish();
}

}  // namespace loom::kin
