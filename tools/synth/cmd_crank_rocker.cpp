// `loom-synth crank-rocker`: Khare–Dave crank-rockers for a swing ψ and crank rotation φ (thesis
// Tables 4.6–4.9): one row per integer β from the upper to the lower bound, or one for --beta.
// Rows at a bound are change-point linkages (μ_min = 0); a note on stderr says so. A row that is no
// mechanism (the null crank at φ = 180°, β = 0) is reported on stderr and the others are printed;
// alone (--beta) it is an error. Lengths carry 8 decimals (some published tables print that many).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"

namespace loom::synth {

namespace {

constexpr int kLengthDecimals = 8;

}  // namespace

void note_near_special_case(std::ostream& err, double psi_deg, double phi_deg) {
  err << "loom-synth: warning: near special case: phi = " << input_value(phi_deg) << " deg is within "
      << input_value(motion::deg(motion::kNearSpecialCase_rad))
      << " deg of 180 + psi = " << input_value(180.0 + psi_deg)
      << " deg: b and c grow like 1/|phi - 180 - psi| towards a limit that depends on the path, not the "
         "case-III linkage (use --phi "
      << input_value(180.0 + psi_deg) << " for that); these lengths are ill-conditioned\n";
}

void run_crank_rocker(const CrankRockerArgs& args, std::ostream& out, std::ostream& err) {
  require_positive_length("--ground", args.ground);
  const double psi = motion::rad(args.psi_deg);
  const motion::CrankRotation phi = crank_rotation(args.phi_deg, args.phi_text);
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

  const CsvFormat f(args.full_precision);
  std::vector<std::string> rows;
  bool near_special = false;
  for (double beta_deg : betas_deg) {
    motion::CrankRockerDesign d;
    try {
      d = motion::khare_dave_crank_rocker(psi, phi, motion::rad(beta_deg), args.ground);
    } catch (const motion::MotionError& e) {
      if (args.has_beta) throw ArgError("--beta " + input_value(beta_deg) + ": " + e.what());
      err << "loom-synth: note: beta_deg=" << input_value(beta_deg) << ": no row: " << e.what() << "\n";
      continue;
    }
    std::ostringstream row;
    write_row(row,
              {f.input(beta_deg), f.length(d.crank, kLengthDecimals), f.length(d.coupler, kLengthDecimals),
               f.length(d.rocker, kLengthDecimals), f.angle_deg(motion::deg(d.mu_min_rad))});
    rows.push_back(row.str());
    if (d.flags & motion::kDesignChangePoint) {
      err << "loom-synth: note: beta_deg=" << input_value(beta_deg)
          << ": beta at a bound, change-point linkage, mu_min = 0\n";
    }
    near_special = near_special || (d.flags & motion::kDesignNearSpecialCase) != 0;
  }
  if (near_special) note_near_special_case(err, args.psi_deg, args.phi_deg);
  out << "beta_deg,a,b,c,mu_min_deg\n";
  for (const std::string& r : rows) out << r;
}

}  // namespace loom::synth
