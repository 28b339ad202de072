// loom-dynamics mass: the beat-up's link mass properties computed from geometry and material, next to
// thesis Table 5.1 as printed and to the formula that reproduces its inertias (half the bar width).
#include <string>

#include "commands.hpp"
#include "loom/cli/csv.hpp"
#include "loom/motion/mass_properties.hpp"

namespace loom::dyncli {

using namespace loom::motion;

CLI::App* add_mass(CLI::App& app) {
  return app.add_subcommand(
      "mass", "Beat-up link masses and inertias (cast iron, 30x10 mm) vs thesis Table 5.1 (CSV)");
}

void run_mass() {
  const BeatUpGeometry g = default_beatup_geometry();
  const BeatUpMasses m = beatup_masses(g);
  const ThesisTable51 t;
  const BarSection sec;
  cli::CsvWriter out(
      "link,length_m,mass_kg,centre_m,inertia_kg_m2,thesis_mass_kg,thesis_inertia_kg_m2,half_width_inertia_"
      "kg_m2");
  const auto link = [&](const char* name, double len, const PlanarInertia& p, double tm, double tj) {
    out.text(name).num(len).num(p.mass_kg).num(p.centre_m.norm()).num(p.inertia_kg_m2).num(tm).num(tj);
    // m(L² + (w/2)²)/12: the formula whose values Table 5.1 prints.
    out.num(p.mass_kg * (len * len + 0.25 * sec.width_m * sec.width_m) / 12.0);
    out.end_row();
  };
  link("crank", g.bar.crank, m.crank, t.m2_kg, t.j2_kg_m2);
  link("coupler", g.bar.coupler, m.coupler, t.m3_kg, t.j3_kg_m2);
  link("rocker", g.beater_arm_m, m.rocker, t.m4_kg, t.j4_kg_m2);
  const PlanarInertia rb = m.rocker_with_beater();
  out.text("rocker_with_beater")
      .num(g.beater_arm_m)
      .num(rb.mass_kg)
      .num(rb.centre_m.norm())
      .num(rb.inertia_kg_m2);
  out.text("").text("").text("");
  out.end_row();
  out.finish();
}

}  // namespace loom::dyncli
