// Fixed-decimal CSV cells for loom-synth (see table_format.hpp): no "-0.000000", no NaN/inf.
#include "loom/cli/table_format.hpp"

#include <cmath>
#include <cstdio>

namespace loom::cli {

std::string CsvFormat::fixed(double v, int decimals) const {
  if (!std::isfinite(v)) {
    throw NonFiniteOutput(std::string("a result is ") + (std::isnan(v) ? "NaN" : "infinite") +
                          " (inputs beyond what double precision can represent here)");
  }
  char buf[512];
  if (full_) {
    std::snprintf(buf, sizeof buf, "%.17g", v == 0.0 ? 0.0 : v);
    return buf;
  }
  // A value that rounds to zero prints as zero, not as "-0.00".
  if (std::fabs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0.0;
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string CsvFormat::input(double v) const {
  if (!full_) return input_value(v);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v == 0.0 ? 0.0 : v);
  return buf;
}

std::string input_value(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v == 0.0 ? 0.0 : v);
  return buf;
}

void write_row(std::ostream& out, std::initializer_list<std::string> cells) {
  bool first = true;
  for (const std::string& c : cells) {
    if (!first) out << ',';
    out << c;
    first = false;
  }
  out << '\n';
}

}  // namespace loom::cli
