// What a call into motion/ refused with, for the motion tests: the MotionError's code (empty when
// the call returned) or its message, so a test can say which typed error an impossible input gets.
#pragma once

#include <optional>
#include <string>

#include "loom/motion/errors.hpp"

namespace loom::test {

template <class F>
std::optional<motion::ErrorCode> error_of(F&& f) {
  try {
    f();
  } catch (const motion::MotionError& e) {
    return e.code();
  }
  return std::nullopt;
}

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const motion::MotionError& e) {
    return e.what();
  }
  return "";
}

}  // namespace loom::test
