// `loom-kin fourbar`: options are link lengths (any one unit, ground = 1 by default) and degrees; the
// linkage is swept over one crank turn on the chosen assembly branch, one CSV row per sample, or
// summarised in one row. Geometric refusals name the length options they come from.
#include "fourbar_cmd.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"

namespace loom::kin {

using cli::eccentricity;
using cli::finite_number;
using cli::positive_number;

namespace {

constexpr const char* kLengthOptions = "--ground/--crank/--coupler/--rocker";

loom::motion::FourBarLink link_of(const std::string& name) {
  using loom::motion::FourBarLink;
  if (name == "crank") return FourBarLink::kCrank;
  if (name == "rocker") return FourBarLink::kRocker;
  return FourBarLink::kCoupler;
}

void warn_near_toggle(const loom::motion::FourBar& m) {
  using namespace loom::motion;
  const GrashofClass cls = classify(m);
  if (cls != GrashofClass::kCrankRocker && cls != GrashofClass::kDoubleCrank) return;
  const TransmissionRange r = transmission_range(m);
  if (r.near_toggle) {
    std::fprintf(
        stderr,
        "loom-kin: warning: near toggle: the transmission angle reaches %.6g deg (|sin mu| = %.3g < %g); "
        "rates there are amplified by 1/|sin mu| and small length errors move the linkage a long way\n",
        deg(std::sin(r.mu_min) <= std::sin(r.mu_max) ? r.mu_min : r.mu_max), r.min_abs_sin_mu,
        kNearToggleSine);
  }
}

void write_summary(const loom::motion::FourBar& m, loom::motion::Branch branch) {
  using namespace loom::motion;
  const GrashofClass cls = classify(m);
  cli::CsvWriter out(
      "grashof,mu_min_deg,mu_max_deg,crank_extended_deg,crank_folded_deg,rocker_extended_deg,"
      "rocker_folded_deg,swing_deg,crank_rotation_deg,time_ratio");
  out.text(grashof_class_name(cls));
  // Cells that do not exist for this class stay empty (never NaN): μ needs a full-turning crank,
  // dead centres need a rocker.
  if (cls == GrashofClass::kCrankRocker || cls == GrashofClass::kDoubleCrank) {
    const TransmissionRange r = transmission_range(m);
    out.num(deg(r.mu_min)).num(deg(r.mu_max));
  } else {
    out.text("").text("");
  }
  if (cls == GrashofClass::kCrankRocker) {
    const DeadCentres dc = dead_centres(m, branch);
    out.num(deg(dc.crank_extended)).num(deg(dc.crank_folded)).num(deg(dc.rocker_extended));
    out.num(deg(dc.rocker_folded)).num(deg(dc.swing)).num(deg(dc.crank_rotation)).num(dc.time_ratio);
  } else {
    for (int i = 0; i < 7; ++i) out.text("");
  }
  out.end_row();
  out.finish();
}

void write_sweep(const FourBarArgs& a, const loom::motion::FourBar& m, loom::motion::Branch branch) {
  using namespace loom::motion;
  const bool point = !a.point_link.empty();
  std::string header = "theta2_deg,theta3_deg,theta4_deg,k3,k4,k3p,k4p,transmission_deg";
  if (point) header += ",point_x,point_y,point_vx,point_vy,point_ax,point_ay";
  cli::CsvWriter out(header);
  // Every class but the change point: a linkage whose crank cannot turn fully (double-rocker,
  // rocker-crank, triple-rocker) is analysed at the crank angles it reaches; the others are left out
  // and counted. The crank angle column is the pose's own, so a gap shows where they were.
  const ReachableSweep cover =
      fourbar_sweep_reachable(m, branch, a.samples, rad(a.start_deg), [&](int i, const FourBarPose& p) {
        out.num(a.start_deg + 360.0 * static_cast<double>(i) / static_cast<double>(a.samples));
        out.num(deg(p.theta3)).num(deg(p.theta4)).num(p.k3).num(p.k4).num(p.k3p).num(p.k4p);
        out.num(deg(p.transmission));
        if (point) {
          const PointMotion pm = point_motion(
              point_coefficients(m, p, link_of(a.point_link), {a.point_x, a.point_y}), a.omega, a.alpha);
          out.num(pm.position.x()).num(pm.position.y()).num(pm.velocity.x()).num(pm.velocity.y());
          out.num(pm.acceleration.x()).num(pm.acceleration.y());
        }
        out.end_row();
      });
  if (cover.solved == 0) {
    throw MotionError(ErrorCode::kNotAssemblable,
                      std::string("the ") + grashof_class_name(classify(m)) +
                          " cannot be assembled at any of the " + std::to_string(a.samples) +
                          " crank angles asked for (--start-deg " + cli::format_number(a.start_deg) +
                          ", --samples " + std::to_string(a.samples) + ")");
  }
  out.finish();
  if (cover.unreachable + cover.at_toggle > 0) {
    std::fprintf(
        stderr,
        "loom-kin: note: the %s's crank cannot reach every angle: %d of %d samples left out (%d beyond its "
        "reach, %d at a toggle)\n",
        grashof_class_name(classify(m)), cover.unreachable + cover.at_toggle, a.samples, cover.unreachable,
        cover.at_toggle);
  }
}

}  // namespace

CLI::App* add_fourbar_command(CLI::App& app, FourBarArgs& a) {
  CLI::App* c = app.add_subcommand(
      "fourbar",
      "Any four-bar (crank input) over one crank turn: angles, kinematic coefficients, transmission; a "
      "linkage whose input cannot turn fully (double-rocker, ...) at the crank angles it reaches");
  c->add_option("--ground", a.ground, "Ground link A0B0 (lengths in its unit)")
      ->check(positive_number())
      ->capture_default_str();
  c->add_option("--crank", a.crank, "Crank A0A")->check(positive_number())->required();
  c->add_option("--coupler", a.coupler, "Coupler AB")->check(positive_number())->required();
  c->add_option("--rocker", a.rocker, "Rocker (output) B0B")->check(positive_number())->required();
  c->add_option("--branch", a.branch, "Assembly: B counter-clockwise (positive) or clockwise of B0->A")
      ->check(CLI::IsMember({"positive", "negative"}))
      ->capture_default_str();
  c->add_option("--samples", a.samples, "Samples over one crank turn")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  c->add_option("--start-deg", a.start_deg, "Crank angle of the first sample")
      ->check(finite_number())
      ->capture_default_str();
  c->add_flag("--summary", a.summary,
              "One row: Grashof class, transmission extremes, dead centres, time ratio");
  CLI::Option* link =
      c->add_option("--point-link", a.point_link, "Append a point on this link: crank, coupler or rocker")
          ->check(CLI::IsMember({"crank", "coupler", "rocker"}));
  c->add_option("--point-x", a.point_x, "Point along its link from the link's first pivot")
      ->check(finite_number())
      ->needs(link);
  c->add_option("--point-y", a.point_y, "Point 90 deg counter-clockwise from the link line")
      ->check(finite_number())
      ->needs(link);
  c->add_option("--omega", a.omega, "Crank speed for the point's velocity and acceleration, rad/s")
      ->check(finite_number())
      ->capture_default_str();
  c->add_option("--alpha", a.alpha, "Crank acceleration for the point's acceleration, rad/s^2")
      ->check(finite_number())
      ->capture_default_str();
  return c;
}

void run_fourbar(const FourBarArgs& a) {
  using namespace loom::motion;
  const FourBar m{a.ground, a.crank, a.coupler, a.rocker};
  const Branch branch = a.branch == "negative" ? Branch::kNegative : Branch::kPositive;
  try {
    warn_near_toggle(m);
    if (a.summary) {
      write_summary(m, branch);
    } else {
      write_sweep(a, m, branch);
    }
  } catch (const MotionError& e) {
    throw MotionError(e.code(), std::string(kLengthOptions) + ": " + e.what());
  }
}

}  // namespace loom::kin
