// Option value checks shared by the offline CLIs: CLI11 validators whose messages CLI11 prefixes with
// the option's name, so every bad value is refused as "--option: why" before any computation, exit 2.
// "nan" and "inf" parse as doubles, so finiteness is checked here too.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <sstream>
#include <string>

namespace loom::cli {

// A number for which `ok` holds; otherwise the message "'<text>' <why>".
template <class Ok>
CLI::Validator number_check(Ok ok, const std::string& why, const std::string& name) {
  return CLI::Validator(
      [ok, why](std::string& s) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
        if (!std::isfinite(v) || !ok(v)) return "'" + s + "' " + why;
        return {};
      },
      name);
}

// A finite decimal number.
inline CLI::Validator finite_number() {
  return number_check([](double) { return true; }, "is not a finite number", "FINITE");
}

// A finite number > 0 (lengths, speeds, forces, masses).
inline CLI::Validator positive_number() {
  return number_check([](double v) { return v > 0.0; }, "must be a finite number > 0", "POSITIVE");
}

// A finite number >= 0 (weights, contact forces).
inline CLI::Validator non_negative_number() {
  return number_check([](double v) { return v >= 0.0; }, "must be a finite number >= 0", "NONNEGATIVE");
}

// A finite number in [lo, hi] (CLI::Range lets NaN through: every comparison with NaN is false).
inline CLI::Validator finite_range(double lo, double hi) {
  std::ostringstream bounds;
  bounds << "[" << lo << ", " << hi << "]";
  return number_check([lo, hi](double v) { return v >= lo && v <= hi; },
                      "must be a finite number in " + bounds.str(), "FLOAT in " + bounds.str());
}

// Eccentricity of the elliptic pitch curves: [0, 1).
inline CLI::Validator eccentricity() {
  return number_check([](double v) { return v >= 0.0 && v < 1.0; },
                      "must be in [0, 1) (e >= 1 is an open curve, not a gear)", "[0,1)");
}

// Eccentricities this close to 1 make the speed ratio ((1+e)/(1-e))^2 exceed 1e6: results are
// printed, flagged as an extreme ratio on stderr.
inline constexpr double kExtremeEccentricity = 0.998;

}  // namespace loom::cli
