// Option value checks for loom-dynamics: CLI11 validators, so a bad value is refused before any
// computation with a message naming the option and the value, and the program exits with status 2.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace loom::dyncli {

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

// A finite number > 0 (speeds, forces, masses).
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

// A finite number >= 0 (weights, contact forces).
inline CLI::Validator non_negative_number() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
        if (!std::isfinite(v) || v < 0.0) return "'" + s + "' must be a finite number >= 0";
        return {};
      },
      "NONNEGATIVE");
}

// Eccentricity of the elliptic pitch curves: [0, 1).
inline CLI::Validator eccentricity() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
        if (!std::isfinite(v) || v < 0.0 || v >= 1.0) return "'" + s + "' must be in [0, 1)";
        return {};
      },
      "[0,1)");
}

}  // namespace loom::dyncli
