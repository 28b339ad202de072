// The board-side subcommands of loomctl: `serve` (what the systemd unit runs: configure, arm, wait for
// the operator) and `ctl` (the operator's client for serve's control socket), plus `--version` and the
// man-style help footer. main() registers them with one call and runs the chosen one after parsing.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace loom::firmware::serve {

const char* version();  // e.g. "0.1.0", from the CMake project version

struct ServeArgs {
  std::string config;  // "" → /etc/loomctl/loom.toml when present, else the embedded default
  std::string scene;   // sim HAL only
  std::string hal = "sim";
  std::string iface;
  std::string state_dir = "/var/lib/loomctl";
  std::string socket;  // "" → /run/loomctl/<loom-id>.sock
  std::string group = "loom";
  std::string loom_id, lcm_url;
  std::uint32_t rows = 0;  // rows per `start` (0: until `stop`)
  double pace = 1.0;       // sim only: run this many times faster than real time
  int rt_priority = 80;
  int cpu = -1;
  // Consecutive overruns that latch loop_overrun; unset → timing.overrun_stop_after on hardware, never in
  // simulation (a paced simulator that falls behind endangers nothing).
  std::optional<std::uint32_t> overrun_stop;
  bool allow_degraded = false, no_telemetry = false;
};
int serve_main(const ServeArgs& a);

struct CtlArgs {
  std::string command;
  std::vector<std::string> args;  // pair/unpair NAME; reload HEAD SLOT [KNOTS]; job VERB [N|DESIGN]
  int hours = 0;                  // pair: 0 → the service's default
  // job add: the carpet's length, at most one (none: the design once). Text as given (the service checks).
  std::string rows, metres, repeat;
  std::string socket;
  std::string loom_id;  // "" → the board's (ctl_socket)
  int timeout_ms = 5000;
  // Where an installed board keeps its loom id and its services' sockets (tests give their own).
  std::string loom_id_file = "/etc/loomctl/loom-id";
  std::string run_dir = "/run/loomctl";
};
int ctl_main(const CtlArgs& a);
// The request line `a` sends (`pair tablet-1 hours=12`, `reload head=2 slot=1 knots=300`); "" and `error`
// set when the words after the command do not fit it.
std::string ctl_request_line(const CtlArgs& a, std::string& error);

// The control socket `ctl` talks to: --socket; else <run_dir>/<id>.sock for --loom-id; else for the
// board's id (LOOMCTL_LOOM_ID= in the loom-id file postinst writes); else the only socket in run_dir.
// `how` says which (for messages). Throws std::runtime_error naming file:line, or what to give, when it
// cannot tell (a malformed id file, several looms' sockets, none at all).
std::string ctl_socket(const CtlArgs& a, std::string& how);

// What to add to a failed connection's error: for EACCES, which group may command the loom and how to
// join it; "" otherwise.
std::string ctl_permission_advice(const std::string& path);

// Adds `serve`, `ctl`, `--version` and the help footer to `app`. After app.parse(), run() executes the
// chosen board subcommand and returns its exit code, or nullopt when another subcommand was chosen.
class BoardCommands {
 public:
  explicit BoardCommands(CLI::App& app);
  std::optional<int> run() const;

 private:
  CLI::App* serve_ = nullptr;
  CLI::App* ctl_ = nullptr;
  std::unique_ptr<ServeArgs> serve_args_ = std::make_unique<ServeArgs>();
  std::unique_ptr<CtlArgs> ctl_args_ = std::make_unique<CtlArgs>();
};

}  // namespace loom::firmware::serve
