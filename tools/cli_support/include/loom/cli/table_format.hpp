// The thesis' table format for loom-synth: numbers with a fixed number of decimals (lengths 6, or 8
// where a published table prints more; angles 2; ratios 4) so a printed table compares digit for digit
// with the thesis; full precision prints round-trip doubles (%.17g) for scripts. Inputs echoed back
// (φ, β, ψ in degrees) keep their shortest faithful form ("169", not "169.000000"), or %.17g with
// full precision. A non-finite value throws NonFiniteOutput (csv.hpp), never prints.
#pragma once

#include <initializer_list>
#include <ostream>
#include <string>

#include "loom/cli/csv.hpp"

namespace loom::cli {

// All of this is offline-tool code (configure-time only).
class CsvFormat {
 public:
  explicit CsvFormat(bool full_precision) : full_(full_precision) {}
  std::string length(double v, int decimals = 6) const { return fixed(v, decimals); }
  std::string angle_deg(double v) const { return fixed(v, 2); }
  std::string ratio(double v) const { return fixed(v, 4); }
  std::string input(double v) const;
  bool full_precision() const { return full_; }

 private:
  std::string fixed(double v, int decimals) const;
  bool full_;
};

// An input echoed back in its shortest faithful form (10 significant digits).
std::string input_value(double v);

void write_row(std::ostream& out, std::initializer_list<std::string> cells);

}  // namespace loom::cli
