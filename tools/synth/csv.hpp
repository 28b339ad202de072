// CSV output of loom-synth. By default numbers carry the thesis' table precision (lengths 6
// decimals, angles 2, ratios 4) so a printed table compares digit for digit with the thesis;
// --full-precision prints round-trip doubles (%.17g) for scripts.
#pragma once

#include <initializer_list>
#include <ostream>
#include <string>

namespace loom::synth {

// All of this is offline-tool code (configure-time only).
class CsvFormat {
 public:
  explicit CsvFormat(bool full_precision) : full_(full_precision) {}
  std::string length(double v) const { return fixed(v, 6); }
  std::string angle_deg(double v) const { return fixed(v, 2); }
  std::string ratio(double v) const { return fixed(v, 4); }

 private:
  std::string fixed(double v, int decimals) const;
  bool full_;
};

// An input echoed back (φ, β, ψ in degrees): its shortest faithful form, "169" not "169.000000".
std::string input_value(double v);

void write_row(std::ostream& out, std::initializer_list<std::string> cells);

}  // namespace loom::synth
