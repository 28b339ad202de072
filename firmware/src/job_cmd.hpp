// `loomctl job add|list|show|remove|start-over`: the carpet job queue in the state directory, offline (the
// running service's queue is changed through it). main() registers them with one line and runs them after
// parsing, as BoardCommands.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>

namespace loom::firmware {

struct JobArgs;

class JobCommands {
 public:
  explicit JobCommands(CLI::App& app);
  ~JobCommands();
  // The chosen job verb's exit code, or nullopt when another subcommand was chosen.
  std::optional<int> run() const;

 private:
  CLI::App* job_ = nullptr;
  std::unique_ptr<JobArgs> args_;
};

}  // namespace loom::firmware
