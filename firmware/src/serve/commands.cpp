// CLI registration of the board subcommands, `loomctl ctl`, --version and the man-style help footer.
#include "loom/firmware/serve/commands.hpp"

#include <grp.h>
#include <pwd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "loom/firmware/serve/control_socket.hpp"
#include "loom/telemetry/channels.hpp"

namespace loom::firmware::serve {

const char* version() {
  return LOOM_VERSION;
}

namespace {

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// The value of LOOMCTL_LOOM_ID= in the id file (shell syntax: comments, optional quotes), "" when the file
// is absent. Throws on a file that is there but unreadable or malformed.
std::string loom_id_from(const std::string& file) {
  std::ifstream in(file);
  if (!in) {
    if (errno == ENOENT) return "";
    throw std::runtime_error("cannot read " + file + ": " + std::strerror(errno));
  }
  std::string line, id;
  int n = 0, at = 0;
  while (std::getline(in, line)) {
    ++n;
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    const std::string key = "LOOMCTL_LOOM_ID=";
    if (line.rfind(key, 0) != 0) continue;
    id = line.substr(key.size());
    if (id.size() >= 2 && (id.front() == '"' || id.front() == '\'') && id.back() == id.front()) {
      id = id.substr(1, id.size() - 2);
    }
    at = n;
  }
  if (at == 0) throw std::runtime_error(file + ": no LOOMCTL_LOOM_ID= line (give --loom-id or --socket)");
  if (auto e = telemetry::loom_id_error(id); !e.empty()) {
    throw std::runtime_error(file + ":" + std::to_string(at) + ": LOOMCTL_LOOM_ID '" + id + "': " + e);
  }
  return id;
}

}  // namespace

std::string ctl_socket(const CtlArgs& a, std::string& how) {
  if (!a.socket.empty()) {
    how = "--socket";
    return a.socket;
  }
  if (!a.loom_id.empty()) {
    how = "--loom-id " + a.loom_id;
    return a.run_dir + "/" + a.loom_id + ".sock";
  }
  if (const std::string id = loom_id_from(a.loom_id_file); !id.empty()) {
    how = "loom id " + id + " from " + a.loom_id_file;
    return a.run_dir + "/" + id + ".sock";
  }
  // No id file (a board set up by hand, a development machine): the only loom served here.
  std::vector<std::string> socks;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(a.run_dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().extension() == ".sock") socks.push_back(it->path().filename().string());
  }
  if (ec && ec != std::errc::no_such_file_or_directory) {
    throw std::runtime_error("cannot list " + a.run_dir + ": " + ec.message() +
                             ctl_permission_advice(a.run_dir));
  }
  std::sort(socks.begin(), socks.end());
  if (socks.size() == 1) {
    how = "the only socket in " + a.run_dir;
    return a.run_dir + "/" + socks[0];
  }
  if (socks.empty()) {
    throw std::runtime_error("which loom? no " + a.loom_id_file + " and no control socket in " + a.run_dir +
                             " (is loomctl serve running? give --loom-id ID or --socket PATH)");
  }
  std::string list;
  for (const std::string& s : socks) list += (list.empty() ? "" : ", ") + s;
  throw std::runtime_error("which loom? " + a.run_dir + " has " + std::to_string(socks.size()) + " (" + list +
                           "): give --loom-id ID");
}

std::string ctl_permission_advice(const std::string& path) {
  // Only when the kernel refuses us (a socket missing or a dead serve are said otherwise).
  if (::access(path.c_str(), R_OK | W_OK) == 0 || errno != EACCES) return "";
  std::string user = "USER";
  if (const passwd* pw = ::getpwuid(::geteuid()); pw != nullptr) user = pw->pw_name;
  if (::getgrnam("loom") == nullptr) {
    return ". Members of group loom may command the loom, but this system has no group loom (is the loomctl "
           "package installed? its postinst makes it)";
  }
  return ". Members of group loom may command the loom: sudo adduser " + user +
         " loom, then log in again (a new group counts from the next login). adduser needs an existing "
         "account: for a new operator, sudo adduser NAME first";
}

namespace {

// `job VERB [N | DESIGN]` as the socket's request: `job show id=3`, `job add design=/abs/path rows=40`.
// The design's path is made absolute here (the service resolves nothing against its own directory).
std::string job_request_line(const CtlArgs& a, std::string& error) {
  const std::size_t n = a.args.size();
  const std::string verb = n > 0 ? a.args[0] : "";
  const bool add = verb == "add", numbered = verb == "show" || verb == "remove" || verb == "start-over";
  if (!add && !numbered && verb != "list") {
    error = "job takes a verb: list, show N, add DESIGN, remove N, start-over N" +
            (verb.empty() ? std::string() : " (got '" + verb + "')");
    return "";
  }
  const std::size_t want = verb == "list" ? 1 : 2;
  if (n != want) {
    error = "job " + verb +
            (want == 1 ? " takes no more words"
             : add     ? " takes DESIGN (the design file)"
                       : " takes N (the job's number)") +
            ", got " + std::to_string(n - 1);
    return "";
  }
  if (!add && (!a.rows.empty() || !a.metres.empty() || !a.repeat.empty())) {
    error = "--rows, --metres and --repeat are for job add only";
    return "";
  }
  std::string line = "job " + verb;
  if (numbered) line += " id=" + a.args[1];
  if (add) {
    std::error_code ec;
    const std::string path = std::filesystem::absolute(a.args[1], ec).lexically_normal().string();
    if (ec || path.find_first_of(" \t\r\n") != std::string::npos) {
      error = "job add " + a.args[1] +
              ": the control socket takes a design path without spaces (rename the file, or add the job with "
              "serve stopped: loomctl job add)";
      return "";
    }
    line += " design=" + path;
    if (!a.rows.empty()) line += " rows=" + a.rows;
    if (!a.metres.empty()) line += " metres=" + a.metres;
    if (!a.repeat.empty()) line += " repeat=" + a.repeat;
  }
  return line;
}

}  // namespace

std::string ctl_request_line(const CtlArgs& a, std::string& error) {
  const std::size_t n = a.args.size();
  std::string request = a.command;
  if (a.command == "pair" || a.command == "unpair") {
    if (n != 1) {
      error = a.command + " takes one NAME (e.g. " + a.command + " tablet-1), got " + std::to_string(n);
      return "";
    }
    request += " " + a.args[0];
  } else if (a.command == "reload") {
    if (n < 2 || n > 3) {
      error = "reload takes HEAD SLOT [KNOTS] (as the heads' request names them: reload 2 1), got " +
              std::to_string(n) + " word(s)";
      return "";
    }
    request += " head=" + a.args[0] + " slot=" + a.args[1];
    if (n == 3) request += " knots=" + a.args[2];
  } else if (a.command == "job") {
    return job_request_line(a, error);
  } else if (n != 0) {
    error = a.command + " takes no argument (got '" + a.args[0] + "')";
    return "";
  }
  if (!a.rows.empty() || !a.metres.empty() || !a.repeat.empty()) {
    error = "--rows, --metres and --repeat are for job add only";
    return "";
  }
  if (a.hours > 0) request += " hours=" + std::to_string(a.hours);
  return request;
}

int ctl_main(const CtlArgs& a) {
  std::string how, path;
  try {
    path = ctl_socket(a, how);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loomctl ctl: %s\n", e.what());
    return 1;
  }
  std::string usage_error;
  const std::string request = ctl_request_line(a, usage_error);
  if (request.empty()) {
    std::fprintf(stderr, "loomctl ctl: %s\n", usage_error.c_str());
    return 2;
  }
  std::string reply;
  try {
    reply = control_request(path, request, a.timeout_ms);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loomctl ctl: %s (%s)%s\n", e.what(), how.c_str(),
                 ctl_permission_advice(path).c_str());
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
  /etc/loomctl/loom-id          this board's loom id (LOOMCTL_LOOM_ID=, made at install; ctl's default)
  /run/loomctl/<loom-id>.sock   serve's control socket (group loom, mode 0660: sudo adduser USER loom)
  /usr/share/loomctl/lcmtypes/  the LCM message types of the telemetry channels

SIGNALS
  weave: SIGUSR1 pause, SIGUSR2 resume, SIGINT/SIGTERM stop (at the next hold point),
         SIGHUP reload the recipe.
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
  serve_
      ->add_option("--config", s.config, "loom config (TOML); default /etc/loomctl/loom.toml, else embedded")
      ->check(CLI::ExistingFile);
  serve_->add_option("--scene", s.scene, "simulation scene (sim HAL)")->check(CLI::ExistingFile);
  serve_->add_option("--hal", s.hal, "sim | socketcan")->check(CLI::IsMember({"sim", "socketcan"}));
  serve_->add_option("--iface", s.iface, "SocketCAN interface (with --hal socketcan), e.g. can0");
  serve_->add_option("--state-dir", s.state_dir,
                     "counters, machine state and fault history (default /var/lib/loomctl)");
  serve_->add_option("--socket", s.socket, "control socket path (default /run/loomctl/<loom-id>.sock)");
  serve_->add_option("--group", s.group, "group given the control socket (default loom; \"\" = none)");
  serve_->add_option("--loom-id", s.loom_id, "loom id (overrides the config)");
  serve_->add_option("--lcm-url", s.lcm_url, "LCM provider URL for telemetry (overrides the config)");
  serve_->add_flag("--no-telemetry", s.no_telemetry, "do not publish LCM telemetry");
  serve_->add_option("--rows", s.rows, "rows woven per start (default 0: until stop)");
  serve_->add_option("--pace", s.pace, "sim HAL: run this many times faster than real time")
      ->check(CLI::Range(0.01, 1000.0));
  serve_
      ->add_option("--rt-priority", s.rt_priority, "SCHED_FIFO priority of the loop thread (0: SCHED_OTHER)")
      ->check(CLI::Range(0, 99));
  serve_->add_option("--cpu", s.cpu, "pin the loop thread to this (isolated) CPU; -1 = any")
      ->check(CLI::Range(-1, 1023));
  serve_->add_option("--overrun-stop", s.overrun_stop,
                     "consecutive overruns that stop the loom safely (0: never; default "
                     "timing.overrun_stop_after on hardware, never in simulation)");
  serve_->add_flag("--allow-degraded", s.allow_degraded, "arm on hardware even if mlockall/SCHED_FIFO fail");

  CtlArgs& c = *ctl_args_;
  ctl_ = app.add_subcommand("ctl", "send an operator command to a running `loomctl serve`");
  ctl_->add_option(
          "command", c.command,
          "start | pause | resume | stop (at row end) | ack (a fault) | status | faults (history and "
          "commands) | next | reload HEAD SLOT [KNOTS] (the weaver reloaded a magazine slot; full "
          "without KNOTS) | job list|show N|add DESIGN|remove N|start-over N (the carpet job queue) | "
          "pair NAME (a code for a panel client) | unpair NAME | pairs")
      ->required()
      ->check(CLI::IsMember({"start", "pause", "resume", "stop", "ack", "status", "faults", "next", "reload",
                             "job", "pair", "unpair", "pairs"}));
  ctl_->add_option("args", c.args,
                   "pair/unpair: the client's name (letters, digits, _ - .); reload: HEAD SLOT [KNOTS]; "
                   "job: VERB [N | DESIGN]");
  auto* rows =
      ctl_->add_option("--rows", c.rows, "job add: the carpet's length in rows (default: the design once)");
  auto* metres = ctl_->add_option("--metres", c.metres,
                                  "job add: the carpet's length in metres, at the loom's rows_per_dm");
  auto* repeat = ctl_->add_option("--repeat", c.repeat, "job add: weave the design this many times");
  rows->excludes(metres)->excludes(repeat);
  metres->excludes(repeat);
  ctl_->add_option("--hours", c.hours, "pair: how long the pairing lasts (default 12)")
      ->check(CLI::Range(1, 168));
  ctl_->add_option("--socket", c.socket, "control socket (default /run/loomctl/<loom-id>.sock)");
  ctl_->add_option(
      "--loom-id", c.loom_id,
      "loom id (default: the board's, LOOMCTL_LOOM_ID in /etc/loomctl/loom-id; without that file "
      "the only socket in /run/loomctl)");
  ctl_->add_option("--timeout-ms", c.timeout_ms, "how long to wait for the reply")
      ->check(CLI::Range(1, 600000));
}

std::optional<int> BoardCommands::run() const {
  if (serve_->parsed()) return serve_main(*serve_args_);
  if (ctl_->parsed()) return ctl_main(*ctl_args_);
  return std::nullopt;
}

}  // namespace loom::firmware::serve
