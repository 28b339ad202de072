// `loom-synth slider-crank`: Söylemez's optimum slider-crank (thesis Table 4.2 / 4.3) for one crank
// rotation φ or a range of them, at λ_opt or a given λ. In a range, a φ with no design (e.g. 180°) is
// reported on stderr and the other rows are printed; a single --phi with no design is an error, and
// so is a range in which no φ has one.
#include <cmath>
#include <sstream>
#include <vector>

#include "commands.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"

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
  const std::vector<double> phis =
      args.has_phi ? std::vector<double>{args.phi_deg} : parse_range(args.phi_range);

  const CsvFormat f(args.full_precision);
  std::ostringstream table;
  std::size_t printed = 0;
  for (double phi_deg : phis) {
    // π − φ exact near 180°: in decimal from --phi's text, from the double for a range's values
    const motion::CrankRotation phi = crank_rotation(phi_deg, args.has_phi ? args.phi_text : std::string());
    motion::SliderCrankDesign d;
    try {
      motion::soylemez_lambda_bounds(phi);
      d = args.has_lambda ? motion::soylemez_slider_crank(args.stroke, phi, args.lambda)
                          : motion::soylemez_slider_crank(args.stroke, phi);
    } catch (const motion::MotionError& e) {
      const std::string arg = args.has_lambda
                                  ? "--phi " + input_value(phi_deg) + " --lambda " + input_value(args.lambda)
                                  : "--phi " + input_value(phi_deg);
      if (args.has_phi) throw ArgError(arg + ": " + e.what());
      err << "loom-synth: note: phi_deg=" << input_value(phi_deg) << ": no row: " << e.what() << "\n";
      continue;
    }
    write_row(table,
              {f.input(phi_deg), f.length(d.mechanism.crank), f.length(d.mechanism.coupler),
               f.length(d.mechanism.offset), f.angle_deg(motion::deg(d.mu_min_rad)), f.ratio(d.lambda)});
    ++printed;
    if (d.flags & motion::kDesignChangePoint) {
      err << "loom-synth: note: phi_deg=" << input_value(phi_deg)
          << ": lambda at a bound, change-point slider-crank (b = a + c), mu_min = 0\n";
    }
  }
  if (printed == 0) throw ArgError("--phi-range " + args.phi_range + ": no phi in the range has a design");
  out << "phi_deg,a,b,c,mu_min_deg,lambda\n" << table.str();
}

}  // namespace loom::synth
