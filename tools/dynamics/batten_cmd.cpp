// loom-dynamics batten: the elliptic-gear batten drive of seed 004 (its dimensions, a = 0.05 m,
// k = 2): the batten's angular acceleration at the beat for e and φ02 against the circular gear, or
// with --search the φ02 that maximises it.
#include <cstdio>
#include <string>

#include "commands.hpp"
#include "loom/cli/csv.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/dynamics_batten.hpp"

namespace loom::dyncli {

using namespace loom::motion;
using cli::eccentricity;
using cli::finite_number;
using cli::positive_number;

CLI::App* add_batten(CLI::App& app, BattenArgs& a) {
  CLI::App* c = app.add_subcommand(
      "batten", "Elliptic-gear batten (004): acceleration gain at the beat vs e = 0 (CSV)");
  c->add_option("--e", a.e, "Eccentricity of the elliptic pitch curves")
      ->check(eccentricity())
      ->capture_default_str();
  CLI::Option* phi =
      c->add_option("--phi02-rad", a.phi02_rad, "Crank orientation on the driven pinion (004 eqn 8)")
          ->check(finite_number());
  CLI::Option* search =
      c->add_flag("--search", a.search, "Search phi02 for the largest acceleration at the beat");
  phi->excludes(search);
  c->add_flag("--scan", a.scan,
              "With --search: print every scanned phi02, then the refined best as the last row");
  c->add_option("--side", a.side,
                "Turning points that are the beat: front (the harder ones at e = 0), psi-max, psi-min")
      ->check(CLI::IsMember({"front", "psi-max", "psi-min"}))
      ->capture_default_str();
  c->add_option("--k", a.k, "Lobes of the pitch curves")->check(CLI::Range(1, 12))->capture_default_str();
  c->add_option("--omega1", a.omega1_rad_s, "Driving-pinion speed (rad/s; the gain does not depend on it)")
      ->check(positive_number())
      ->capture_default_str();
  c->add_option("--samples", a.samples, "Samples per turn for locating turning points (then bisection)")
      ->check(CLI::Range(16, 1000000))
      ->capture_default_str();
  c->add_option("--scan-points", a.scan_points, "phi02 samples over one period before refinement")
      ->check(CLI::Range(3, 100000))
      ->capture_default_str();
  return c;
}

namespace {

// Per visit (004's double swing visits the beat side twice per turn): each visit's gain and crank
// angle, and which visit is the beat (the harder one with the circular gear). Columns for visits a
// linkage does not make stay empty.
constexpr int kVisitColumns = 2;

void row(cli::CsvWriter& out, const BattenGain& g) {
  out.num(g.eccentricity).num(g.phi02_rad).num(deg(g.phi02_rad)).text(batten_beat_side_name(g.side));
  out.num(g.accel_rad_s2).num(g.circular_accel_rad_s2).num(g.gain).num(g.phi1_rad);
  out.num(static_cast<double>(g.visits.size()));
  for (int v = 0; v < kVisitColumns; ++v) {
    if (v < static_cast<int>(g.visits.size())) {
      out.num(deg(g.visits[static_cast<std::size_t>(v)].crank_rad))
          .num(g.visits[static_cast<std::size_t>(v)].gain);
    } else {
      out.text("").text("");
    }
  }
  out.num(g.beat_visit + 1)
      .num(g.visits.empty() ? 0.0 : g.visits[static_cast<std::size_t>(g.beat_visit)].gain);
  out.end_row();
}

}  // namespace

void run_batten(const CLI::App& cmd, const BattenArgs& a) {
  if (!a.search && cmd.count("--phi02-rad") == 0) throw UsageError("batten: give --phi02-rad X, or --search");
  if (a.scan && !a.search) throw UsageError("batten: --scan needs --search");
  const BattenLinkage linkage(batten_004_dims());
  const EllipticGearPair gear(kBatten004GearA_m, a.e, a.k);
  const BattenBeatSide side = a.side == "psi-max"   ? BattenBeatSide::kPsiMax
                              : a.side == "psi-min" ? BattenBeatSide::kPsiMin
                                                    : batten_front_side(linkage, a.omega1_rad_s, a.samples);
  if (gear.near_degenerate()) {
    std::fprintf(
        stderr,
        "loom-dynamics: warning: extreme ratio: --e %.17g is near 1: the crank speed swings by %.3g:1 and "
        "the gain is its square; the results are finite but ill-conditioned\n",
        a.e, gear.max_speed_ratio() * gear.max_speed_ratio());
  }
  cli::CsvWriter out(
      "e,phi02_rad,phi02_deg,side,beat_accel_rad_s2,circular_accel_rad_s2,gain,beat_phi1_rad,visits,"
      "visit1_crank_deg,visit1_gain,visit2_crank_deg,visit2_gain,beat_visit,beat_visit_gain");
  if (a.search) {
    const BattenSearch s = batten_best_phi02(linkage, gear, side, a.omega1_rad_s, a.scan_points, a.samples);
    if (a.scan) {
      for (const BattenGain& g : s.scan) row(out, g);
    }
    row(out, s.best);
  } else {
    row(out, batten_gain(linkage, gear, a.phi02_rad, side, a.omega1_rad_s, a.samples));
  }
  out.finish();
}

}  // namespace loom::dyncli
