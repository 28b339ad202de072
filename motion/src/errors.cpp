// Names of motion error codes, for messages and tests.
#include "loom/motion/errors.hpp"

namespace loom::motion {

const char* error_code_name(ErrorCode c) {
  switch (c) {
    case ErrorCode::kInvalidInput:
      return "invalid_input";
    case ErrorCode::kNotAssemblable:
      return "not_assemblable";
    case ErrorCode::kNotCrank:
      return "not_crank";
    case ErrorCode::kOutOfBounds:
      return "out_of_bounds";
    case ErrorCode::kSingular:
      return "singular";
    case ErrorCode::kNoConvergence:
      return "no_convergence";
    case ErrorCode::kWrongBranch:
      return "wrong_branch";
  }
  return "?";
}

}  // namespace loom::motion
