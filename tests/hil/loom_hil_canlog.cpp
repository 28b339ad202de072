// loom-hil-canlog — the HIL tests' judge: reads a `candump -L` log and checks the CANopen exchange
// (start-up order, cyclic PDOs, heartbeat-loss reaction) or just counts frames. Exit 0 = holds,
// 1 = violated (the first violation is printed), 2 = bad input (arguments or an unreadable log line).
#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "canlog.hpp"
#include "protocol_checks.hpp"

namespace {

constexpr int kExitViolated = 1;
constexpr int kExitBadInput = 2;

bool load(const std::string& path, std::vector<loom::hil::Frame>& frames) {
  std::ifstream in(path);
  if (!in) {
    std::cerr << "loom-hil-canlog: cannot open log '" << path << "'\n";
    return false;
  }
  std::string error;
  if (!loom::hil::read_candump_log(in, frames, error)) {
    std::cerr << "loom-hil-canlog: " << path << ": " << error << "\n";
    return false;
  }
  return true;
}

int report(const std::string& what, const loom::hil::CheckResult& r) {
  for (const auto& note : r.notes) std::cout << "  " << note << "\n";
  if (!r.ok) {
    std::cout << what << ": FAILED: " << r.failure << "\n";
    return kExitViolated;
  }
  std::cout << what << ": ok\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Check a candump -L log of loomctl against simulated CiA 402 drives"};
  app.require_subcommand(1);
  std::string log;
  std::vector<int> nodes;
  double heartbeat_ms = 100.0;
  int periods = 3;

  auto* summary = app.add_subcommand("summary", "count frames per CANopen service");
  summary->add_option("log", log, "candump -L log")->required();

  auto* weave = app.add_subcommand("weave", "NMT/SDO start-up order, then SYNC with RPDOs and TPDOs");
  weave->add_option("log", log, "candump -L log")->required();
  weave->add_option("--nodes", nodes, "drive node ids, e.g. 1,2,3")
      ->required()
      ->delimiter(',')
      ->check(CLI::Range(1, 127));

  auto* loss = app.add_subcommand("heartbeat-loss", "fault reaction after the drives' heartbeat stopped");
  loss->add_option("log", log, "candump -L log")->required();
  loss->add_option("--nodes", nodes, "drive node ids, e.g. 1,2,3")
      ->required()
      ->delimiter(',')
      ->check(CLI::Range(1, 127));
  loss->add_option("--heartbeat-ms", heartbeat_ms, "heartbeat producer time (ms)")
      ->check(CLI::Range(1.0, 65535.0));
  loss->add_option("--periods", periods, "allowed heartbeat periods until the fault reaction")
      ->check(CLI::Range(1, 100));
  double master_cycle_ms = 0.0;
  loss->add_option("--master-cycle-ms", master_cycle_ms,
                   "judge on the master's clock: its SYNCs, one per cycle of this length (0: wall time)")
      ->check(CLI::Range(0.0, 1000.0));

  int io_node = 4, emcy_node = 0, master = 0x7F;
  double consumer_ms = 150.0, slack_ms = 500.0;
  auto* io = app.add_subcommand("io", "every valve and sensor of the CiA 401 I/O node crossed the bus");
  io->add_option("log", log, "candump -L log")->required();
  io->add_option("--node", io_node, "I/O node id")->check(CLI::Range(1, 127));
  bool second_switches = false;
  io->add_flag("--second-switches", second_switches,
               "inputs 16..21 (0x6000:03) carry the safety sensors' second switches: each seen, each equal "
               "to its first");
  auto* emcy = app.add_subcommand("emcy-stop", "quick stop of every drive within one cycle of an EMCY");
  emcy->add_option("log", log, "candump -L log")->required();
  emcy->add_option("--nodes", nodes, "drive node ids")->required()->delimiter(',')->check(CLI::Range(1, 127));
  emcy->add_option("--emcy-node", emcy_node, "node whose EMCY is checked")
      ->required()
      ->check(CLI::Range(1, 127));
  auto* mloss = app.add_subcommand("master-loss", "every node's 0x1016 consumer reacts when the master dies");
  mloss->add_option("log", log, "candump -L log")->required();
  mloss->add_option("--nodes", nodes, "node ids")->required()->delimiter(',')->check(CLI::Range(1, 127));
  mloss->add_option("--master", master, "master node id")->check(CLI::Range(1, 127));
  mloss->add_option("--consumer-ms", consumer_ms, "consumer time (ms)")->check(CLI::Range(1.0, 65535.0));
  mloss->add_option("--slack-ms", slack_ms, "allowed lateness (the VM is not real-time)")
      ->check(CLI::Range(0.0, 10000.0));

  loom::hil::KnottingWiring knots;
  auto* knotting =
      app.add_subcommand("knotting", "the heads tied every knot of the row, safely, seen on the wire");
  knotting->add_option("log", log, "candump -L log")->required();
  knotting->add_option("--node", io_node, "I/O node id")->check(CLI::Range(1, 127));
  knotting->add_option("--gripper-bits", knots.gripper_bits, "output bit of each head's gripper")
      ->required()
      ->delimiter(',');
  knotting->add_option("--cutter-bits", knots.cutter_bits, "output bit of each head's cutter")
      ->required()
      ->delimiter(',');
  knotting->add_option("--yarn-bits", knots.yarn_bits, "input bit of each head's yarn-present switch")
      ->required()
      ->delimiter(',');
  knotting->add_option("--selector-nodes", knots.selector_nodes, "each head's colour-selector drive")
      ->required()
      ->delimiter(',')
      ->check(CLI::Range(1, 127));
  knotting->add_option("--carriage-node", knots.carriage_node, "the carriage drive")
      ->check(CLI::Range(1, 127));
  knotting->add_option("--knots-per-head", knots.knots_per_head, "knots each head ties in the log")
      ->required()
      ->check(CLI::Range(1, 100000));

  double inhibit_ms = 10.0;
  int min_moves = 1;
  auto* pp = app.add_subcommand("profile-position",
                                "profile-position drives: RPDO1 on change only, set-point handshake, TPDO1 "
                                "inhibit time");
  pp->add_option("log", log, "candump -L log")->required();
  pp->add_option("--nodes", nodes, "drive node ids")->required()->delimiter(',')->check(CLI::Range(1, 127));
  pp->add_option("--inhibit-ms", inhibit_ms, "TPDO1 inhibit time the master writes (0x1800:03)")
      ->check(CLI::Range(0.1, 6553.5));
  pp->add_option("--min-moves", min_moves, "set-points each node must have had")
      ->check(CLI::Range(0, 100000));

  int max_late = 1000000;
  auto* lag =
      app.add_subcommand("feedback-lag", "each drive's TPDO1 answers the SYNC right before it (the rig)");
  lag->add_option("log", log, "candump -L log")->required();
  lag->add_option("--nodes", nodes, "drive node ids")->required()->delimiter(',')->check(CLI::Range(1, 127));
  lag->add_option("--max-cycles-late", max_late,
                  "fail when a TPDO1 trails its SYNC by more (default: report only)")
      ->check(CLI::Range(0, 1000000));

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "loom-hil-canlog: " << e.what() << "\n";
    return kExitBadInput;
  }

  std::vector<loom::hil::Frame> frames;
  if (!load(log, frames)) return kExitBadInput;
  std::cout << log << ": " << loom::hil::describe(loom::hil::summarize(frames)) << "\n";
  if (summary->parsed()) return 0;
  if (weave->parsed()) return report("weave protocol", loom::hil::check_weave_protocol(frames, nodes));
  if (io->parsed())
    return report("I/O traffic", loom::hil::check_io_traffic(frames, io_node, second_switches));
  if (knotting->parsed()) return report("knotting", loom::hil::check_knotting(frames, io_node, knots));
  if (pp->parsed()) {
    return report("profile position",
                  loom::hil::check_profile_position(frames, nodes, inhibit_ms * 1e-3, min_moves));
  }
  if (lag->parsed()) return report("feedback lag", loom::hil::check_feedback_lag(frames, nodes, max_late));
  if (emcy->parsed()) return report("EMCY stop", loom::hil::check_emcy_stop(frames, nodes, emcy_node));
  if (mloss->parsed()) {
    return report("master loss",
                  loom::hil::check_master_loss(frames, nodes, master, consumer_ms * 1e-3, slack_ms * 1e-3));
  }
  return report("heartbeat loss", loom::hil::check_heartbeat_loss(frames, nodes, heartbeat_ms * 1e-3, periods,
                                                                  {}, master_cycle_ms * 1e-3));
}
