// Typed errors of the kinematics/dynamics module. Design and analysis functions are configure-time
// code: when an input is impossible they throw MotionError with a code a caller can test and a message
// naming the offending quantity — never a silent NaN. RT-path functions (table lookups) never throw.
#pragma once

#include <stdexcept>
#include <string>

namespace loom::motion {

enum class ErrorCode {
  kInvalidInput,    // a parameter outside its domain (negative length, e >= 1, φ = 180° exactly, ...)
  kNotAssemblable,  // the linkage cannot close at this input (no real solution)
  kNotCrank,        // Grashof says the input link cannot fully rotate
  kOutOfBounds,     // a design variable outside its feasible bounds (e.g. β beyond its limits)
  kSingular,        // a linear system or Jacobian is singular (toggle, change point)
  kNoConvergence,   // an iterative solver did not converge within its budget
  kWrongBranch,     // an iterative solver converged to the other assembly branch
};

const char* error_code_name(ErrorCode c);

class MotionError : public std::runtime_error {
 public:
  MotionError(ErrorCode code, const std::string& what) : std::runtime_error(what), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

}  // namespace loom::motion
