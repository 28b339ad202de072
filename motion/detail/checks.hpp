// Input checks shared by the linkage constructors and solvers in motion/: every refusal is a
// MotionError whose message starts with the mechanism's name and names the field and its value,
// so a loom builder reading it knows which number to change. Internal, configure-time only.
#pragma once

#include <cmath>
#include <sstream>
#include <string>

#include "loom/motion/errors.hpp"

namespace loom::motion::detail {

// configure-time only. Throws MotionError(code, "<who>: <what>").
[[noreturn]] inline void fail(const char* who, ErrorCode code, const std::string& what) {
  throw MotionError(code, std::string(who) + ": " + what);
}

// configure-time only. kInvalidInput unless v is a finite length > 0 ("<who>: <field> = v<unit>:
// must be ..."); `unit` is " m" for SI lengths, "" for lengths in the caller's own unit.
inline void require_positive_length(const char* who, const char* field, double v, const char* unit = " m") {
  if (!std::isfinite(v) || !(v > 0.0)) {
    std::ostringstream os;
    os << field << " = " << v << unit << ": must be a finite length > 0";
    fail(who, ErrorCode::kInvalidInput, os.str());
  }
}

// configure-time only. kInvalidInput unless v is finite; `unit` is printed after the value
// (" m", " rad" or "").
inline void require_finite(const char* who, const char* field, double v, const char* unit) {
  if (!std::isfinite(v)) {
    std::ostringstream os;
    os << field << " = " << v << unit << ": must be finite";
    fail(who, ErrorCode::kInvalidInput, os.str());
  }
}

// configure-time only. kInvalidInput unless a sweep has at least one sample.
inline void require_samples(const char* who, int samples) {
  if (samples < 1)
    fail(who, ErrorCode::kInvalidInput, "samples = " + std::to_string(samples) + ": must be >= 1");
}

}  // namespace loom::motion::detail
