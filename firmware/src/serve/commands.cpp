// CLI registration of the board subcommands, `loomctl ctl`, --version and the man-style help footer.
#include "loom/firmware/serve/commands.hpp"

#include <cstdio>

#include "loom/firmware/serve/control_socket.hpp"

namespace loom::firmware::serve {

const char* version() { return LOOM_VERSION; }

int ctl_main(const CtlArgs& a) {
  const std::string path = a.socket.empty() ? "/run/loomctl/" + a.loom_id + ".sock" : a.socket;
  std::string request = a.command;
  if (!a.name.empty()) request += " " + a.name;
  if (a.hours > 0) request += " hours=" + std::to_string(a.hours);
  std::string reply;
  try {
    reply = control_request(path, request, a.timeout_ms);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loomctl ctl: %s\n", e.what());
    return 1;
  }
  // Only `ok ...` (and the reading commands' text) means done: a refusal says why and exits 1.
  const bool error = reply.empty() || reply.rfind("error:", 0) == 0 || reply.rfind("refused:", 0) == 0;
  std::fputs(reply.c_str(), error ? stderr : stdout);
  return error ? 1 : 0;
}

namespace {
constexpr const char* kFooter = R"(
EXIT STATUS
  weave: 0 rows woven, 2 bad input (nothing started), 3 ended in a fault, 4 hardware not armed.
  serve: 0 stopped by the service manager, 2 bad input, 4 could not arm (real-time or CAN set-up).
  ctl:   0 done (the reply is "ok ..."), 1 refused ("refused: why"), failed or no answer, 2 bad usage.

FILES
  /etc/loomctl/loom.toml        the loom's configuration (serve's default --config; a conffile)
  /var/lib/loomctl/             serve's state: counters.json, sim-state.bin, faults.log(.1)
  /run/loomctl/<loom-id>.sock   serve's control socket (group loom, mode 0660)
  /usr/share/loomctl/lcmtypes/  the LCM message types of the telemetry channels

SIGNALS
  weave: SIGUSR1 pause, SIGUSR2 resume, SIGINT/SIGTERM stop (at the next hold point), SIGHUP reload the recipe.
  serve: SIGINT/SIGTERM stop at the next hold point (a row's end, between picks or knot cycles), then exit.

SEE ALSO
  loomctl serve --help, loomctl ctl --help, loom-monitor(1), lcm-logger(1), cyclictest(8))";
}  // namespace

BoardCommands::BoardCommands(CLI::App& app) {
  app.set_version_flag("--version", std::string("loomctl ") + version());
  app.footer(kFooter);

  ServeArgs& s = *serve_args_;
  serve_ = app.add_subcommand("serve",
                              "run as the loom's service: configure, arm and wait for operator commands "
                              "(control socket, I/O-node buttons); what the systemd unit runs");
  serve_->add_option("--config", s.config, "loom config (TOML); default /etc/loomctl/loom.toml, else embedded")
      ->check(CLI::ExistingFile);
  serve_->add_option("--scene", s.scene, "simulation scene (sim HAL)")->check(CLI::ExistingFile);
  serve_->add_option("--hal", s.hal, "sim | socketcan")->check(CLI::IsMember({"sim", "socketcan"}));
  serve_->add_option("--iface", s.iface, "SocketCAN interface (with --hal socketcan), e.g. can0");
  serve_->add_option("--state-dir", s.state_dir, "counters, machine state and fault history (default /var/lib/loomctl)");
  serve_->add_option("--socket", s.socket, "control socket path (default /run/loomctl/<loom-id>.sock)");
  serve_->add_option("--group", s.group, "group given the control socket (default loom; \"\" = none)");
  serve_->add_option("--loom-id", s.loom_id, "loom id (overrides the config)");
  serve_->add_option("--lcm-url", s.lcm_url, "LCM provider URL for telemetry (overrides the config)");
  serve_->add_flag("--no-telemetry", s.no_telemetry, "do not publish LCM telemetry");
  serve_->add_option("--rows", s.rows, "rows woven per start (default 0: until stop)");
  serve_->add_option("--pace", s.pace, "sim HAL: run this many times faster than real time")
      ->check(CLI::Range(0.01, 1000.0));
  serve_->add_option("--rt-priority", s.rt_priority, "SCHED_FIFO priority of the loop thread (0: SCHED_OTHER)")
      ->check(CLI::Range(0, 99));
  serve_->add_option("--cpu", s.cpu, "pin the loop thread to this (isolated) CPU; -1 = any")->check(CLI::Range(-1, 1023));
  serve_->add_option("--overrun-stop", s.overrun_stop, "consecutive overruns that stop the loom safely (0: never; default timing.overrun_stop_after on hardware, never in simulation)");
  serve_->add_flag("--allow-degraded", s.allow_degraded, "arm on hardware even if mlockall/SCHED_FIFO fail");

  CtlArgs& c = *ctl_args_;
  ctl_ = app.add_subcommand("ctl", "send an operator command to a running `loomctl serve`");
  ctl_->add_option("command", c.command,
                   "start | pause | resume | stop (at row end) | ack (a fault) | status | faults (history and "
                   "commands) | next | pair NAME (a code for a panel client) | unpair NAME | pairs")
      ->required()
      ->check(CLI::IsMember({"start", "pause", "resume", "stop", "ack", "status", "faults", "next", "pair", "unpair",
                             "pairs"}));
  ctl_->add_option("name", c.name, "pair/unpair: the client's name (letters, digits, _ - .)");
  ctl_->add_option("--hours", c.hours, "pair: how long the pairing lasts (default 12)")->check(CLI::Range(1, 168));
  ctl_->add_option("--socket", c.socket, "control socket (default /run/loomctl/<loom-id>.sock)");
  ctl_->add_option("--loom-id", c.loom_id, "loom id (default loom1)");
  ctl_->add_option("--timeout-ms", c.timeout_ms, "how long to wait for the reply")->check(CLI::Range(1, 600000));
}

std::optional<int> BoardCommands::run() const {
  if (serve_->parsed()) return serve_main(*serve_args_);
  if (ctl_->parsed()) return ctl_main(*ctl_args_);
  return std::nullopt;
}

}  // namespace loom::firmware::serve
