// Command-line value checks for loom-kin: CLI11 validators whose messages CLI11 prefixes with the
// option's name, so every bad value is reported as "--option: why" before any computation starts.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace loom::kin {

// A number for which `ok` holds ("nan" and "inf" parse as doubles, so finiteness is checked here
// too); otherwise the message "'<text>' <why>".
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

// A finite number > 0 (lengths, speeds).
inline CLI::Validator positive_number() {
  return number_check([](double v) { return v > 0.0; }, "must be a finite number > 0", "POSITIVE");
}

// Eccentricity of the elliptic pitch curves: [0, 1).
inline CLI::Validator eccentricity() {
  return number_check([](double v) { return v >= 0.0 && v < 1.0; },
                      "must be in [0, 1) (e >= 1 is an open curve, not a gear)", "[0,1)");
}

}  // namespace loom::kin
