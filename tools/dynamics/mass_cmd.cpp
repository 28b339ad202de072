// loom-dynamics mass: the beat-up's link mass properties computed from geometry and material, next to
// thesis Table 5.1 as printed and to the formula that reproduces its inertias (half the bar width).
#include <string>

#include "commands.hpp"
#include "csv.hpp"
#include "loom/motion/mass_properties.hpp"

namespace loom::dyncli {

using namespace loom::motion;

CLI::App* add_mass(CLI::App& app) {
  return app.add_subcommand("mass", "Beat-up link masses and inertias (cast iron, 30x10 mm) vs thesis Table 5.1 (CSV)");
}

void run_mass() {
  const BeatUpGeometry g = default_beatup_geometry();
  const BeatUpMasses m = beatup_masses(g);
  const ThesisTable51 t;
  const BarSection sec;
  std::string out =
      "link,length_m,mass_kg,centre_m,inertia_kg_m2,thesis_mass_kg,thesis_inertia_kg_m2,half_width_inertia_kg_m2\n";
  const auto link = [&](const char* name, double len, const PlanarInertia& p, double tm, double tj) {
    put(out, std::string(name));
    put(out, len);
    put(out, p.mass_kg);
    put(out, p.centre_m.norm());
    put(out, p.inertia_kg_m2);
    put(out, tm);
    put(out, tj);
    // m(L² + (w/2)²)/12: the formula whose values Table 5.1 prints.
    put(out, p.mass_kg * (len * len + 0.25 * sec.width_m * sec.width_m) / 12.0, true);
  };
  link("crank", g.bar.crank, m.crank, t.m2_kg, t.j2_kg_m2);
  link("coupler", g.bar.coupler, m.coupler, t.m3_kg, t.j3_kg_m2);
  link("rocker", g.beater_arm_m, m.rocker, t.m4_kg, t.j4_kg_m2);
  const PlanarInertia rb = m.rocker_with_beater();
  out += "rocker_with_beater,";
  put(out, g.beater_arm_m);
  put(out, rb.mass_kg);
  put(out, rb.centre_m.norm());
  put(out, rb.inertia_kg_m2);
  out += ",,\n";
  emit(out);
}

}  // namespace loom::dyncli
