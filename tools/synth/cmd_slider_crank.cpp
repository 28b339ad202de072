// `loom-synth slider-crank`: Söylemez's optimum slider-crank (thesis Table 4.2 / 4.3) for one crank
// rotation φ or a range of them, at λ_opt or a given λ. Every row is computed before any is
// printed, so a bad φ in a range gives an error and no partial table.
#include <cmath>
#include <sstream>
#include <vector>

#include "commands.hpp"
#include "csv.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/synthesis.hpp"

namespace loom::synth {

namespace {

constexpr long kMaxRows = 1000000;

double parse_number(const std::string& text, const std::string& whole) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v)) {
    throw ArgError("--phi-range " + whole + ": '" + text +
                   "' is not a finite number (expected first:last[:step] in degrees)");
  }
  return v;
}

// "first:last[:step]" → the φ values, first + i·step up to last (inclusive, no drift).
std::vector<double> parse_range(const std::string& spec) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  std::string part;
  while (std::getline(ss, part, ':')) parts.push_back(part);
  if (!spec.empty() && spec.back() == ':') parts.push_back("");
  if (parts.size() < 2 || parts.size() > 3) {
    throw ArgError("--phi-range " + spec + ": expected first:last[:step] in degrees, e.g. 90:179");
  }
  const double first = parse_number(parts[0], spec);
  const double last = parse_number(parts[1], spec);
  const double step = parts.size() == 3 ? parse_number(parts[2], spec) : 1.0;
  if (!(step > 0.0)) throw ArgError("--phi-range " + spec + ": step must be > 0");
  if (last < first) throw ArgError("--phi-range " + spec + ": last must not be below first");
  const double count = std::floor((last - first) / step + 1e-9) + 1.0;
  if (count > static_cast<double>(kMaxRows)) {
    throw ArgError("--phi-range " + spec + ": more than 1000000 rows");
  }
  std::vector<double> out;
  for (long i = 0; i < static_cast<long>(count); ++i) out.push_back(first + static_cast<double>(i) * step);
  return out;
}

}  // namespace

void require_positive_length(const char* name, double v) {
  if (!std::isfinite(v) || !(v > 0.0)) {
    throw ArgError(std::string(name) + " " + input_value(v) + ": must be a finite length > 0");
  }
}

void run_slider_crank(const SliderCrankArgs& args, std::ostream& out, std::ostream& err) {
  if (args.has_phi == !args.phi_range.empty()) {
    throw ArgError("--phi / --phi-range: give exactly one of them");
  }
  require_positive_length("--stroke", args.stroke);
  const std::vector<double> phis = args.has_phi ? std::vector<double>{args.phi_deg}
                                                : parse_range(args.phi_range);

  std::vector<motion::SliderCrankDesign> designs;
  designs.reserve(phis.size());
  for (double phi_deg : phis) {
    const double phi = motion::rad(phi_deg);
    blame("--phi " + input_value(phi_deg), [&] { return motion::soylemez_lambda_bounds(phi); });
    if (args.has_lambda) {
      designs.push_back(blame("--lambda " + input_value(args.lambda), [&] {
        return motion::soylemez_slider_crank(args.stroke, phi, args.lambda);
      }));
    } else {
      designs.push_back(motion::soylemez_slider_crank(args.stroke, phi));
    }
  }

  const CsvFormat f(args.full_precision);
  out << "phi_deg,a,b,c,mu_min_deg,lambda\n";
  for (std::size_t i = 0; i < designs.size(); ++i) {
    const motion::SliderCrankDesign& d = designs[i];
    write_row(out, {input_value(phis[i]), f.length(d.mechanism.crank), f.length(d.mechanism.coupler),
                    f.length(d.mechanism.offset), f.angle_deg(motion::deg(d.mu_min_rad)),
                    f.ratio(d.lambda)});
    if (d.flags & motion::kDesignChangePoint) {
      err << "loom-synth: note: phi_deg=" << input_value(phis[i])
          << ": lambda at a bound, change-point slider-crank (b = a + c), mu_min = 0\n";
    }
  }
}

}  // namespace loom::synth
