// `loom-kin needle`: options in the paper's units (mm, degrees) converted to SI at the boundary,
// the six-bar swept over one turn, one CSV row per sample. --rates appends the angular velocities
// and accelerations and the needle's velocity and acceleration at --rpm.
#include "needle_cmd.hpp"

#include <cstdio>
#include <string>

#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/needle.hpp"

namespace loom::kin {

using cli::eccentricity;
using cli::finite_number;
using cli::positive_number;

CLI::App* add_needle_command(CLI::App& app, NeedleArgs& a) {
  CLI::App* c = app.add_subcommand("needle", "Tufting-needle six-bar (002) over one main-shaft turn");
  c->add_option("--samples", a.samples, "Samples over one turn")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  const auto len = [&](const char* name, double& v, const char* what) {
    c->add_option(name, v, what)->check(positive_number())->capture_default_str();
  };
  len("--l1-mm", a.l1_mm, "Crank OA");
  len("--l2-mm", a.l2_mm, "Coupler AB");
  len("--l3-mm", a.l3_mm, "Rocker CB");
  len("--l4-mm", a.l4_mm, "Arm CD, rigid with l3");
  len("--l5-mm", a.l5_mm, "Connecting rod DE");
  len("--l6-mm", a.l6_mm, "Needle bar EF");
  c->add_option("--x1-mm", a.x1_mm, "Horizontal offset of rocker pivot C from the main shaft O")
      ->check(finite_number())
      ->capture_default_str();
  c->add_option("--h1-mm", a.h1_mm, "Vertical offset of rocker pivot C from the main shaft O")
      ->check(finite_number())
      ->capture_default_str();
  c->add_option("--x2-mm", a.x2_mm, "Horizontal offset of the needle line from C")
      ->check(finite_number())
      ->capture_default_str();
  c->add_option("--beta1-deg", a.beta1_deg, "Fixed angle between l3 and l4")
      ->check(finite_number())
      ->capture_default_str();
  c->add_option("--rocker-side", a.rocker_side,
                "Rocker pin B on the side of the line O-C away from the needle (002) or toward it")
      ->check(CLI::IsMember({"away", "toward"}))
      ->capture_default_str();
  c->add_option("--rod-side", a.rod_side,
                "Rod D-E hanging from the arm down to the needle bar (002's Fig. 2, theta5 in the third "
                "quadrant) or standing above it (the mirror image)")
      ->check(CLI::IsMember({"hanging", "standing"}))
      ->capture_default_str();
  c->add_option("--rpm", a.rpm, "Main-shaft speed for --rates")
      ->check(positive_number())
      ->capture_default_str();
  c->add_flag("--rates", a.rates, "Append angular velocities/accelerations and needle velocity/acceleration");
  return c;
}

void run_needle(const NeedleArgs& a) {
  using namespace loom::motion;
  NeedleDims d{};
  d.l1_m = a.l1_mm * 1e-3;
  d.l2_m = a.l2_mm * 1e-3;
  d.l3_m = a.l3_mm * 1e-3;
  d.l4_m = a.l4_mm * 1e-3;
  d.l5_m = a.l5_mm * 1e-3;
  d.l6_m = a.l6_mm * 1e-3;
  d.x1_m = a.x1_mm * 1e-3;
  d.x2_m = a.x2_mm * 1e-3;
  d.h1_m = a.h1_mm * 1e-3;
  d.beta1_rad = rad(a.beta1_deg);
  NeedleBranch b;
  b.rocker =
      a.rocker_side == "toward" ? NeedleRockerSide::kPinTowardNeedle : NeedleRockerSide::kPinAwayFromNeedle;
  b.rod = a.rod_side == "standing" ? NeedleRodSide::kStandingRod : NeedleRodSide::kHangingRod;
  const NeedleLinkage n(d, b);
  const double omega1 = a.rpm * kTwoPi / 60.0;

  std::string header = "theta1_deg,theta2_deg,theta3_deg,theta4_deg,theta5_deg,needle_mm";
  if (a.rates) {
    header +=
        ",omega2_rad_s,omega3_rad_s,omega4_rad_s,omega5_rad_s,alpha2_rad_s2,alpha3_rad_s2,"
        "alpha4_rad_s2,alpha5_rad_s2,needle_v_m_s,needle_a_m_s2";
  }
  cli::CsvWriter out(header);
  long i = 0;
  needle_sweep(n, a.samples, omega1, [&](const NeedleState& s) {
    out.num(360.0 * static_cast<double>(i++) / static_cast<double>(a.samples));
    out.num(deg(s.theta2_rad)).num(deg(s.theta3_rad)).num(deg(s.theta4_rad)).num(deg(s.theta5_rad));
    out.num(s.needle_m * 1e3);
    if (a.rates) {
      for (double v : {s.omega2_rad_s, s.omega3_rad_s, s.omega4_rad_s, s.omega5_rad_s, s.alpha2_rad_s2,
                       s.alpha3_rad_s2, s.alpha4_rad_s2, s.alpha5_rad_s2, s.needle_v_m_s, s.needle_a_m_s2}) {
        out.num(v);
      }
    }
    out.end_row();
  });
  out.finish();
}

}  // namespace loom::kin
