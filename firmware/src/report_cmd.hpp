// `loomctl report job N [--format text|csv|json]`: a carpet job's production record (SQLite, in the state
// directory), read-only (serve may be writing it). Registered by main() with one line, as BoardCommands.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>

namespace loom::firmware {

struct ReportArgs;

class ReportCommands {
 public:
  explicit ReportCommands(CLI::App& app);
  ~ReportCommands();
  std::optional<int> run() const;  // nullopt when another subcommand was chosen

 private:
  CLI::App* report_ = nullptr;
  std::unique_ptr<ReportArgs> args_;
};

}  // namespace loom::firmware
