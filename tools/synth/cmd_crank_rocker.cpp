// `loom-synth crank-rocker`: Khare–Dave crank-rockers for a swing ψ and crank rotation φ (thesis
// Tables 4.6–4.9): one row per integer β from the upper to the lower bound, or one for --beta.
// Rows at a bound are change-point linkages (μ_min = 0); a note on stderr says so.
#include <cmath>
#include <vector>

#include "commands.hpp"
#include "csv.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/synthesis.hpp"

namespace loom::synth {

namespace {

void note_degenerate(std::ostream& err, double beta_deg, unsigned flags) {
  if (flags & motion::kDesignNullCrank) {
    err << "loom-synth: note: beta_deg=" << input_value(beta_deg)
        << ": lower bound at phi = 180: zero-length crank and rocker (not a mechanism), mu_min = 0"
           " (limit from inside: 90 - psi/2)\n";
  } else if (flags & motion::kDesignChangePoint) {
    err << "loom-synth: note: beta_deg=" << input_value(beta_deg)
        << ": beta at a bound, change-point linkage, mu_min = 0\n";
  }
}

}  // namespace

void run_crank_rocker(const CrankRockerArgs& args, std::ostream& out, std::ostream& err) {
  require_positive_length("--ground", args.ground);
  const double psi = motion::rad(args.psi_deg);
  const double phi = motion::rad(args.phi_deg);
  const motion::BetaBounds bounds =
      blame("--psi " + input_value(args.psi_deg) + " --phi " + input_value(args.phi_deg),
            [&] { return motion::khare_dave_beta_bounds(psi, phi); });

  std::vector<double> betas_deg;
  if (args.has_beta) {
    betas_deg.push_back(args.beta_deg);
  } else {
    // Integer degrees inside the bounds; the slack absorbs the bounds' radian round trip.
    const long top = static_cast<long>(std::floor(motion::deg(bounds.upper_rad) + 1e-9));
    const long bottom = static_cast<long>(std::ceil(motion::deg(bounds.lower_rad) - 1e-9));
    for (long b = top; b >= bottom; --b) betas_deg.push_back(static_cast<double>(b));
    if (betas_deg.empty()) {
      err << "loom-synth: note: no integer beta in [" << motion::deg(bounds.lower_rad) << ", "
          << motion::deg(bounds.upper_rad) << "] deg; use --beta\n";
    }
  }

  std::vector<motion::CrankRockerDesign> designs;
  for (double beta_deg : betas_deg) {
    designs.push_back(blame("--beta " + input_value(beta_deg), [&] {
      return motion::khare_dave_crank_rocker(psi, phi, motion::rad(beta_deg), args.ground);
    }));
  }

  const CsvFormat f(args.full_precision);
  out << "beta_deg,a,b,c,mu_min_deg\n";
  for (std::size_t i = 0; i < designs.size(); ++i) {
    const motion::CrankRockerDesign& d = designs[i];
    write_row(out, {input_value(betas_deg[i]), f.length(d.crank), f.length(d.coupler),
                    f.length(d.rocker), f.angle_deg(motion::deg(d.mu_min_rad))});
    note_degenerate(err, betas_deg[i], d.flags);
  }
}

}  // namespace loom::synth
