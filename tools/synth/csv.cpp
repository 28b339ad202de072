// CSV formatting for loom-synth (see csv.hpp): fixed decimals without "-0.000000", or %.17g.
#include "csv.hpp"

#include <cmath>
#include <cstdio>

namespace loom::synth {

std::string CsvFormat::fixed(double v, int decimals) const {
  char buf[64];
  if (full_) {
    std::snprintf(buf, sizeof buf, "%.17g", v == 0.0 ? 0.0 : v);
    return buf;
  }
  // A value that rounds to zero prints as zero, not as "-0.00".
  if (std::fabs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0.0;
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
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

}  // namespace loom::synth
