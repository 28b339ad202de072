// What a call into motion/ refused with, for the motion tests: the MotionError's code (empty when
// the call returned) or its message, so a test can say which typed error an impossible input gets.
#pragma once

#include <gtest/gtest.h>

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

// A typed refusal is expected: no error at all fails the test (and kSingular stands in for "none").
template <class F>
motion::ErrorCode code_of_call(F&& f) {
  const auto code = error_of(f);
  if (!code) ADD_FAILURE() << "expected a MotionError";
  return code.value_or(motion::ErrorCode::kSingular);
}

}  // namespace loom::test
