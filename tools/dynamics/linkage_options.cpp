// See linkage_options.hpp. Order of precedence: explicit option > config file > the thesis' loom.
#include "linkage_options.hpp"

#include "loom/cli/numbers.hpp"
#include "loom/cli/run.hpp"
#include "loom/config/config.hpp"

namespace loom::dyncli {

using namespace loom::motion;

void add_linkage_options(CLI::App* c, LinkageArgs& a) {
  c->add_option("--config", a.config, "Loom config (TOML): the beat-up of its [beatup] section")
      ->check(CLI::ExistingFile);
  const auto len = [&](const char* name, double& v, const char* what) {
    c->add_option(name, v, what)->check(cli::positive_number());
  };
  len("--crank-m", a.crank_m, "Crank A0A (default: config or thesis 0.058)");
  len("--coupler-m", a.coupler_m, "Coupler AB (default: config or thesis 0.189)");
  len("--rocker-m", a.rocker_m, "Rocker B0B (default: config or thesis 0.232)");
  len("--ground-m", a.ground_m, "Ground A0B0 (default: config or thesis 0.213)");
  len("--beater-arm-m", a.beater_arm_m,
      "Beater tip distance from the rocker pivot (default: config or 0.301)");
  len("--warp-depth-m", a.warp_depth_m, "Beater travel inside the warp (default: config or 0.05)");
  c->add_option("--branch", a.branch, "Assembly branch (default: config or positive)")
      ->check(CLI::IsMember({"positive", "negative"}));
  c->add_option("--fell-at", a.fell_at,
                "Dead centre at which the beater meets the fell (default: config or extended)")
      ->check(CLI::IsMember({"extended", "folded"}));
  c->add_option("--beater-kg", a.beater_kg,
                "Beater mass at the beater arm (default: config's beater_mass_kg or 2.5)")
      ->check(cli::non_negative_number());
  len("--crank-kg", a.crank_kg, "Crank mass, as a uniform bar (default: cast-iron bar of the section)");
  len("--coupler-kg", a.coupler_kg, "Coupler mass, as a uniform bar");
  len("--rocker-kg", a.rocker_kg, "Rocker bar mass (without the beater), as a uniform bar");
  c->add_option("--bar-width-m", a.bar_width_m, "Link bar width in the plane of motion")
      ->check(cli::positive_number())
      ->capture_default_str();
  c->add_option("--bar-thickness-m", a.bar_thickness_m, "Link bar thickness")
      ->check(cli::positive_number())
      ->capture_default_str();
  c->add_option("--density-kg-m3", a.density_kg_m3, "Link material density")
      ->check(cli::positive_number())
      ->capture_default_str();
}

namespace {

// A uniform bar of the given mass: same centre, inertia scaled with the mass.
void set_mass(PlanarInertia& body, double mass_kg) {
  const double f = mass_kg / body.mass_kg;
  body.mass_kg = mass_kg;
  body.inertia_kg_m2 *= f;
}

}  // namespace

Linkage make_linkage(const CLI::App& c, const LinkageArgs& a) {
  Linkage l;
  l.geometry = default_beatup_geometry();
  double beater_kg = 2.5;
  if (!a.config.empty()) {
    // The loom's own machine description, read (and checked) exactly as loomctl reads it.
    loom::firmware::LoomConfig cfg;
    try {
      cfg = loom::firmware::load_loom_config(a.config);
    } catch (const loom::firmware::ConfigError& e) {
      throw cli::UsageError(e.what());
    }
    l.geometry = cfg.machine_spec.beatup;
    beater_kg = cfg.machine_spec.beater_mass_kg;
    if (cfg.recipe.beat_force_target_n > 0.0) {
      l.config_beat_force_target_n = cfg.recipe.beat_force_target_n;
    } else {
      l.config_crank_speed_rad_s = cfg.recipe.crank_speed_rad_s;
    }
  }
  BeatUpGeometry& g = l.geometry;
  const auto given = [&](const char* name) { return c.count(name) > 0; };
  if (given("--crank-m")) g.bar.crank = a.crank_m;
  if (given("--coupler-m")) g.bar.coupler = a.coupler_m;
  if (given("--rocker-m")) g.bar.rocker = a.rocker_m;
  if (given("--ground-m")) g.bar.ground = a.ground_m;
  if (given("--beater-arm-m")) g.beater_arm_m = a.beater_arm_m;
  if (given("--warp-depth-m")) g.warp_depth_m = a.warp_depth_m;
  if (given("--branch")) g.branch = a.branch == "negative" ? Branch::kNegative : Branch::kPositive;
  if (given("--fell-at")) g.fell_at = a.fell_at == "folded" ? FellSide::kFolded : FellSide::kExtended;
  if (given("--beater-kg")) beater_kg = a.beater_kg;
  BarSection section;
  section.width_m = a.bar_width_m;
  section.thickness_m = a.bar_thickness_m;
  l.masses = beatup_masses(g, beater_kg, section, a.density_kg_m3);
  if (given("--crank-kg")) set_mass(l.masses.crank, a.crank_kg);
  if (given("--coupler-kg")) set_mass(l.masses.coupler, a.coupler_kg);
  if (given("--rocker-kg")) set_mass(l.masses.rocker, a.rocker_kg);
  return l;
}

}  // namespace loom::dyncli
