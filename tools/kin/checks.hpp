// Command-line value checks for loom-kin: CLI11 validators whose messages CLI11 prefixes with the
// option's name, so every bad value is reported as "--option: why" before any computation starts.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace loom::kin {

// A finite decimal number ("nan" and "inf" parse as doubles, so they need their own refusal).
inline CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
        if (!std::isfinite(v)) return "'" + s + "' is not a finite number";
        return {};
      },
      "FINITE");
}

// A finite number > 0 (lengths, speeds).
inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
        if (!std::isfinite(v) || !(v > 0.0)) return "'" + s + "' must be a finite number > 0";
        return {};
      },
      "POSITIVE");
}

// Eccentricity of the elliptic pitch curves: [0, 1).
inline CLI::Validator eccentricity() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
        if (!std::isfinite(v) || v < 0.0 || v >= 1.0)
          return "'" + s + "' must be in [0, 1) (e >= 1 is an open curve, not a gear)";
        return {};
      },
      "[0,1)");
}

}  // namespace loom::kin
