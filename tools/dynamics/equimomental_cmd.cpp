// loom-dynamics equimomental: a link's three equimomental point masses (points 120° apart at one
// distance l = sqrt(I_O/m) from the link origin), for one link given on the command line or for every
// link of the carpet-scraping machine's published tables (the original links and the balanced ones).
// Each row carries the body rebuilt from its point masses, so the equivalence is visible in the output.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "commands.hpp"
#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/equimomental.hpp"

namespace loom::dyncli {

using namespace loom::motion;

namespace {

// A link as the tables print it: mass, centre at (d, θ) in the link frame, inertia about the link
// origin (the point-mass equations' I: Σ m_j l_j²).
struct TableLink {
  const char* name;
  double mass_kg, d_m, theta_deg, inertia_kg_m2;
};

// The scraping machine's seven links before balancing (Table 1: inertia printed in 1e-3 kg m²).
constexpr std::array<TableLink, 7> kOriginal{{
    {"1", 0.3263, 0.0057, 0.0, 0.19e-3},
    {"2", 2.3178, 0.1089, 0.0, 40.02e-3},
    {"3", 0.6393, 0.0474, 0.0, 2.76e-3},
    {"4", 1.7060, 0.1714, 0.0, 68.24e-3},
    {"5", 1.4119, 0.1195, 0.0, 23.35e-3},
    {"6", 4.6232, 0.4182, 0.0, 1086.60e-3},
    {"7", 1.4119, 0.1195, 0.0, 23.35e-3},
}};

// The same links after mass redistribution (Table 2, first block).
constexpr std::array<TableLink, 7> kBalanced{{
    {"1", 0.326, 0.036, -19.30, 0.0004},
    {"2", 5.274, 0.115, 156.99, 0.1544},
    {"3", 0.639, 0.099, -68.88, 0.0062},
    {"4", 8.530, 0.120, -158.10, 0.1224},
    {"5", 1.412, 0.193, -7.53, 0.0525},
    {"6", 4.623, 0.239, -49.14, 0.4521},
    {"7", 1.412, 0.193, -1.72, 0.0525},
}};

void write_link(cli::CsvWriter& out, const TableLink& t, double offset_deg) {
  const Eigen::Vector2d centre =
      t.d_m * Eigen::Vector2d(std::cos(rad(t.theta_deg)), std::sin(rad(t.theta_deg)));
  const EquimomentalSystem e = equimomental_three_origin(t.mass_kg, centre, t.inertia_kg_m2, rad(offset_deg));
  if (t.inertia_kg_m2 < t.mass_kg * t.d_m * t.d_m) {
    std::fprintf(
        stderr,
        "loom-dynamics: warning: link %s: inertia about the origin %.6g kg m^2 is below m d^2 = %.6g kg m^2 "
        "(no rigid body has it; rounded at the m d^2 <= I bound?): a point mass is negative\n",
        t.name, t.inertia_kg_m2, t.mass_kg * t.d_m * t.d_m);
  }
  const PlanarInertia back = from_point_masses(e.points);
  out.text(t.name).num(t.mass_kg).num(t.d_m).num(t.theta_deg).num(t.inertia_kg_m2).num(e.radius_m);
  for (const PointMass& p : e.points) out.num(p.mass_kg);
  out.num(offset_deg).text(e.all_positive ? "yes" : "no");
  out.num(back.mass_kg).num(back.centre_m.norm()).num(deg(std::atan2(back.centre_m.y(), back.centre_m.x())));
  out.num(back.inertia_about(Eigen::Vector2d::Zero()));
  out.end_row();
}

}  // namespace

CLI::App* add_equimomental(CLI::App& app, EquimomentalArgs& a) {
  CLI::App* c = app.add_subcommand(
      "equimomental",
      "Three equimomental point masses of a link (120 deg apart at l = sqrt(I_O/m)): one link from "
      "--mass/--centre-d/--centre-theta-deg/--inertia, or every link of the carpet-scraping machine "
      "(--table original|balanced) (CSV)");
  CLI::Option* mass = c->add_option("--mass", a.mass_kg, "Link mass, kg")->check(cli::positive_number());
  c->add_option("--centre-d", a.centre_d_m, "Distance of the mass centre from the link origin, m")
      ->check(cli::non_negative_number())
      ->needs(mass)
      ->capture_default_str();
  c->add_option("--centre-theta-deg", a.centre_theta_deg,
                "Direction of the mass centre in the link frame, deg")
      ->check(cli::finite_number())
      ->needs(mass)
      ->capture_default_str();
  CLI::Option* inertia =
      c->add_option("--inertia", a.inertia_kg_m2,
                    "Moment of inertia about the link origin (the point masses' I = sum m_j l^2), kg m^2")
          ->check(cli::non_negative_number())
          ->needs(mass);
  mass->needs(inertia);
  c->add_option("--offset-deg", a.offset_deg,
                "Direction of the first point mass (the others at +120 and +240 deg); the default faces "
                "the mass centre, which keeps every mass >= 0")
      ->check(cli::finite_number());
  c->add_option("--table", a.table, "A published table instead of one link: original or balanced")
      ->check(CLI::IsMember({"original", "balanced"}))
      ->excludes(mass)
      ->capture_default_str();
  return c;
}

void run_equimomental(const CLI::App& cmd, const EquimomentalArgs& a) {
  cli::CsvWriter out(
      "link,mass_kg,centre_d_m,centre_theta_deg,inertia_origin_kg_m2,l_m,m1_kg,m2_kg,m3_kg,offset_deg,all_"
      "positive,"
      "rebuilt_mass_kg,rebuilt_centre_d_m,rebuilt_centre_theta_deg,rebuilt_inertia_origin_kg_m2");
  const bool offset_given = cmd.count("--offset-deg") > 0;
  const auto offset_for = [&](const TableLink& t) { return offset_given ? a.offset_deg : t.theta_deg; };
  if (cmd.count("--mass") > 0) {
    const TableLink t{"link", a.mass_kg, a.centre_d_m, a.centre_theta_deg, a.inertia_kg_m2};
    write_link(out, t, offset_for(t));
  } else {
    for (const TableLink& t : a.table == "balanced" ? kBalanced : kOriginal)
      write_link(out, t, offset_for(t));
  }
  out.finish();
}

}  // namespace loom::dyncli
