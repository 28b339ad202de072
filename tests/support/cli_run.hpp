// Runs a command line (stdout and stderr together) and returns its exit code and output: for tests of
// the product's command-line contract (exit codes, one-line errors).
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace loom::test {

struct CliRun {
  int exit_code;
  std::string output;
};

inline CliRun run_command(const std::string& command_line) {
  FILE* p = popen((command_line + " 2>&1").c_str(), "r");
  if (p == nullptr) return {-1, "popen failed"};
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) out += buf;
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

}  // namespace loom::test
