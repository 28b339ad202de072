// One convention for the offline CLIs' failures: every refusal is one line on stderr naming the
// option or quantity, and exit status 2; --help exits 0. Offline-tool code.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <stdexcept>

#include "loom/cli/csv.hpp"
#include "loom/motion/errors.hpp"

namespace loom::cli {

// A bad combination of options (each value valid alone), or a file that cannot be read or written.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses argv into `app`, then runs `body`; maps every failure to its message and exit code 2.
template <class Body>
int run_cli(const char* prog, CLI::App& app, int argc, char** argv, Body&& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    body();
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: error: %s\n", prog, e.what());
    return 2;
  } catch (const motion::MotionError& e) {
    std::fprintf(stderr, "%s: error (%s): %s\n", prog, motion::error_code_name(e.code()), e.what());
    return 2;
  } catch (const NonFiniteOutput& e) {
    std::fprintf(stderr, "%s: error (non-finite result): %s\n", prog, e.what());
    return 2;
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "%s: error: %s\n", prog, e.what());
    return 2;
  }
  return 0;
}

}  // namespace loom::cli
