// A fresh, empty directory for the running test, <tmp>/loom_<prefix>_<pid>_<test name>: tests that run at
// once (ctest -j) never share one, and one left by a crashed run is emptied first.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace loom::test {

inline std::filesystem::path fresh_test_dir(const std::string& prefix) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  ("loom_" + prefix + "_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace loom::test
