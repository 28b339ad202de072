// loom-dynamics balance: shaking balance of the default beat-up (seed 003's method) — counterweights on
// the crank and rocker, and/or redistribution of every link's mass — with RMS shaking force and moment
// before and after, the optimiser's stop reason, and optionally its convergence trace and SVG plots.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/design/balancing.hpp"
#include "svg_plot.hpp"

namespace loom::dyncli {

using namespace loom::motion;
using cli::non_negative_number;
using cli::positive_number;

CLI::App* add_balance(CLI::App& app, BalanceArgs& a) {
  CLI::App* c = app.add_subcommand("balance",
                                   "Shaking-force/moment balancing of the beat-up (003), before/after (CSV)");
  c->add_option("--w1", a.w1, "Weight of RMS shaking force (relative to unbalanced)")
      ->check(non_negative_number())
      ->capture_default_str();
  c->add_option("--w2", a.w2, "Weight of RMS shaking moment (relative to unbalanced)")
      ->check(non_negative_number())
      ->capture_default_str();
  c->add_option("--method", a.method, "counterweight, redistribution or both")
      ->check(CLI::IsMember({"counterweight", "redistribution", "both"}))
      ->capture_default_str();
  c->add_option("--crank-rad-s", a.crank_rad_s, "Constant crank speed of the balanced motion")
      ->check(positive_number())
      ->capture_default_str();
  c->add_option("--samples", a.samples, "Instants per crank turn (003's delta)")
      ->check(CLI::Range(3, 1000000))
      ->capture_default_str();
  c->add_option("--max-counterweight-kg", a.max_counterweight_kg, "Upper bound on each counterweight")
      ->check(positive_number())
      ->capture_default_str();
  c->add_option("--counterweight-thickness-m", a.counterweight_thickness_m,
                "Thickness of the cast-iron counterweight discs")
      ->check(positive_number())
      ->capture_default_str();
  c->add_option("--xtol", a.xtol_rel, "SLSQP relative tolerance on the design variables")
      ->check(cli::finite_range(1e-15, 0.5))
      ->capture_default_str();
  c->add_option("--max-evaluations", a.max_evaluations, "SLSQP evaluation budget per start")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  c->add_option("--trace", a.trace, "Write every objective evaluation (convergence) as CSV to this file");
  c->add_option("--svg-force", a.svg_force,
                "Plot shaking force magnitude vs crank angle, before/after, to this SVG");
  c->add_option("--svg-moment", a.svg_moment,
                "Plot shaking moment vs crank angle, before/after, to this SVG");
  add_linkage_options(c, a.linkage);
  return c;
}

namespace {

// Shaking load over the samples for given link bodies (payload added back).
std::vector<ShakingLoad> history(const LinkageMotionSamples& s, const std::vector<PlanarInertia>& bodies) {
  std::vector<PlanarInertia> total;
  for (std::size_t i = 0; i < s.links.size(); ++i) total.push_back(combine(bodies[i], s.links[i].payload));
  std::vector<ShakingLoad> h;
  for (std::size_t k = 0; k < s.samples; ++k) {
    h.push_back(shaking_load(total, std::span(s.motion).subspan(k * s.links.size(), s.links.size()),
                             s.moment_about_m));
  }
  return h;
}

void common_columns(cli::CsvWriter& out, const BalanceResult& r) {
  out.num(r.before.force_n).num(r.after.force_n).num(100.0 * r.force_reduction());
  out.num(r.before.moment_nm).num(r.after.moment_nm).num(100.0 * r.moment_reduction());
  out.num(r.objective_before).num(r.objective_after).num(static_cast<double>(r.evaluations));
  out.text(r.stop_reason).num(r.converged ? 1.0 : 0.0);
  out.end_row();
}

}  // namespace

void run_balance(const CLI::App& cmd, const BalanceArgs& a) {
  if (!(a.w1 + a.w2 > 0.0)) throw UsageError("balance: --w1 and --w2 are both 0: nothing to minimise");
  const Linkage linkage = make_linkage(cmd, a.linkage);
  const BeatUpDynamics d(linkage.geometry, linkage.masses);
  // The crank speed: the option, else the config's speed or the speed of its beat-force target.
  double speed = a.crank_rad_s;
  if (cmd.count("--crank-rad-s") == 0 && linkage.config_crank_speed_rad_s)
    speed = *linkage.config_crank_speed_rad_s;
  if (cmd.count("--crank-rad-s") == 0 && !linkage.config_crank_speed_rad_s &&
      linkage.config_beat_force_target_n) {
    speed = d.crank_speed_for_beat_force(*linkage.config_beat_force_target_n);
  }
  const LinkageMotionSamples s = beatup_balancing_samples(d, speed, a.samples);
  BalanceOptions o;
  o.w1 = a.w1;
  o.w2 = a.w2;
  o.counterweight_max_kg = a.max_counterweight_kg;
  o.counterweight_thickness_m = a.counterweight_thickness_m;
  o.xtol_rel = a.xtol_rel;
  o.max_evaluations = a.max_evaluations;
  std::vector<BalanceResult> results;
  if (a.method != "redistribution") results.push_back(balance_with_counterweights(s, o));
  if (a.method != "counterweight") results.push_back(balance_by_redistribution(s, o));

  cli::CsvWriter out(
      "method,link,mass_kg,radius_m,angle_deg,inertia_kg_m2,rms_force_before_n,rms_force_after_n,"
      "force_reduction_pct,rms_moment_before_nm,rms_moment_after_nm,moment_reduction_pct,objective_before,"
      "objective_after,evaluations,stop_reason,converged");
  for (const BalanceResult& r : results) {
    if (r.method == "counterweight") {
      // One row per counterweight: its mass, where its centre sits, and its own (disc) inertia.
      for (const Counterweight& c : r.counterweights) {
        out.text(r.method)
            .text(c.link)
            .num(c.mass_kg)
            .num(c.radius_m)
            .num(deg(c.angle_rad))
            .num(c.inertia_kg_m2);
        common_columns(out, r);
      }
    } else {
      // One row per link: its new mass, centre of mass (distance, angle) and central inertia.
      for (std::size_t i = 0; i < r.links_after.size(); ++i) {
        const PlanarInertia& b = r.links_after[i];
        out.text(r.method).text(s.links[i].name).num(b.mass_kg).num(b.centre_m.norm());
        out.num(deg(std::atan2(b.centre_m.y(), b.centre_m.x()))).num(b.inertia_kg_m2);
        common_columns(out, r);
      }
    }
  }
  if (!a.trace.empty()) {
    std::ofstream f(a.trace, std::ios::binary);
    if (!f) throw UsageError("--trace: cannot write '" + a.trace + "'");
    std::string t = "method,evaluation,objective,rms_force_n,rms_moment_nm\n";
    std::size_t non_finite = 0;
    for (const BalanceResult& r : results) {
      for (const OptimiserStep& st : r.trace) {
        // The optimiser probes designs the model cannot evaluate (a link mass or inertia driven out of
        // its domain gives NaN/inf): those evaluations are left out of the file and counted, never written.
        if (!std::isfinite(st.objective) || !std::isfinite(st.rms.force_n) ||
            !std::isfinite(st.rms.moment_nm)) {
          ++non_finite;
          continue;
        }
        t += r.method + "," + std::to_string(st.evaluation) + "," + cli::format_number(st.objective) + "," +
             cli::format_number(st.rms.force_n) + "," + cli::format_number(st.rms.moment_nm) + "\n";
      }
    }
    f << t;
    if (!f.flush()) throw UsageError("--trace: cannot write '" + a.trace + "'");
    if (non_finite > 0) {
      std::fprintf(
          stderr,
          "loom-dynamics: note: --trace: %zu evaluations with a non-finite objective (the optimiser probing "
          "outside the model's domain) left out of %s; their numbers are gaps in the evaluation column\n",
          non_finite, a.trace.c_str());
    }
  }
  if (!a.svg_force.empty() || !a.svg_moment.empty()) {
    std::vector<PlanarInertia> original;
    for (const BalancingLink& l : s.links) original.push_back(l.body);
    Chart force{"Beat-up shaking force", "crank angle (deg)", "|shaking force| (N)", {}, {}};
    Chart moment{"Beat-up shaking moment about A0", "crank angle (deg)", "shaking moment (N m)", {}, {}};
    for (std::size_t k = 0; k < s.samples; ++k)
      force.x.push_back(360.0 * static_cast<double>(k) / static_cast<double>(s.samples));
    moment.x = force.x;
    const auto add = [&](const std::string& name, const std::vector<PlanarInertia>& bodies) {
      Series f{name, {}}, m{name, {}};
      for (const ShakingLoad& l : history(s, bodies)) {
        f.y.push_back(l.force_n.norm());
        m.y.push_back(l.moment_nm);
      }
      force.series.push_back(f);
      moment.series.push_back(m);
    };
    add("unbalanced", original);
    for (const BalanceResult& r : results) add(r.method, r.links_after);
    if (!a.svg_force.empty() && !write_svg(force, a.svg_force))
      throw UsageError("--svg-force: cannot write '" + a.svg_force + "'");
    if (!a.svg_moment.empty() && !write_svg(moment, a.svg_moment))
      throw UsageError("--svg-moment: cannot write '" + a.svg_moment + "'");
  }
  out.finish();
}

}  // namespace loom::dyncli
