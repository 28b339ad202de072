// loom-sim-drive: simulated CiA 402 servo drives on a (v)CAN interface, so the firmware's CANopen master
// can be tested end to end without hardware. Runs until SIGINT/SIGTERM; bad arguments exit 2.
//   loom-sim-drive --iface vcan0 --nodes 1,2,3 [--counts-per-unit A,B,C] [--initial-position a,b,c]
#include <poll.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/socket_can_bus.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) {
  g_stop = 1;
}

std::int64_t monotonic_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + ts.tv_nsec / 1000;
}

int usage_error(const std::string& message) {
  std::cerr << "loom-sim-drive: " << message << "\n";
  return 2;
}

// Default scaling of the loom's axes by node position: crank and helix in counts/rad, carriage in
// counts/m (same defaults as the master's CanAxisPortConfig).
double default_counts_per_unit(std::size_t i) {
  return i == 1 ? loom::drivers::kDefaultCountsPerM : loom::drivers::kDefaultCountsPerRad;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulated CiA 402 servo drives (CSP) on a CAN interface"};
  std::string iface;
  std::vector<int> nodes{1, 2, 3};
  std::vector<double> counts_per_unit;
  std::vector<double> initial_position;
  std::uint32_t max_step_counts = 0;
  bool verbose = false;
  app.add_option("--iface", iface, "CAN interface, e.g. vcan0")->required();
  app.add_option("--nodes", nodes, "node ids, comma separated (1..127)")->delimiter(',');
  app.add_option("--counts-per-unit", counts_per_unit,
                 "counts per SI unit per node (rad or m); default 2^20/2π, 2^20/0.01 m, 2^20/2π")
      ->delimiter(',');
  app.add_option("--initial-position", initial_position, "initial position per node in SI units")
      ->delimiter(',');
  app.add_option("--max-step-counts", max_step_counts,
                 "largest target step per SYNC before a following-error fault (0 = off)");
  app.add_flag("--verbose", verbose, "print NMT and drive state changes");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return usage_error(e.what());
  }

  std::set<int> seen;
  for (int n : nodes) {
    if (n < 1 || n > 127) return usage_error("--nodes: node id " + std::to_string(n) + " is outside 1..127");
    if (!seen.insert(n).second) return usage_error("--nodes: node id " + std::to_string(n) + " given twice");
  }
  if (nodes.empty()) return usage_error("--nodes: at least one node id is needed");
  if (!counts_per_unit.empty() && counts_per_unit.size() != nodes.size()) {
    return usage_error("--counts-per-unit: " + std::to_string(counts_per_unit.size()) + " values for " +
                       std::to_string(nodes.size()) + " nodes");
  }
  if (!initial_position.empty() && initial_position.size() != nodes.size()) {
    return usage_error("--initial-position: " + std::to_string(initial_position.size()) + " values for " +
                       std::to_string(nodes.size()) + " nodes");
  }
  std::vector<loom::sim_can::SimDriveConfig> configs;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double cpu = counts_per_unit.empty() ? default_counts_per_unit(i) : counts_per_unit[i];
    if (!(cpu > 0.0) || !std::isfinite(cpu)) {
      return usage_error("--counts-per-unit: value " + std::to_string(cpu) + " for node " +
                         std::to_string(nodes[i]) + " must be a positive number");
    }
    const double x = initial_position.empty() ? 0.0 : initial_position[i] * cpu;
    if (!std::isfinite(x) || std::abs(x) > 2147483647.0) {
      return usage_error("--initial-position: value for node " + std::to_string(nodes[i]) +
                         " does not fit a 32-bit position in counts");
    }
    loom::sim_can::SimDriveConfig c;
    c.node_id = static_cast<std::uint8_t>(nodes[i]);
    c.initial_position = static_cast<std::int32_t>(std::lround(x));
    c.max_step_counts = max_step_counts;
    configs.push_back(c);
  }

  auto opened = loom::drivers::SocketCanBus::open(iface);
  if (!opened) {
    std::cerr << "loom-sim-drive: " << opened.error() << "\n";
    return 1;
  }
  loom::drivers::SocketCanBus& bus = *opened.value();

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  loom::sim_can::SimDriveRack rack(bus, configs);
  rack.power_on(monotonic_us());
  std::cerr << "loom-sim-drive: " << nodes.size() << " drive(s) on " << iface << ", nodes";
  for (int n : nodes) std::cerr << ' ' << n;
  std::cerr << std::endl;

  std::vector<std::pair<loom::drivers::NmtState, loom::hal::DriveState>> shown(rack.size());
  while (g_stop == 0) {
    const std::int64_t now = monotonic_us();
    const std::int64_t deadline = rack.next_deadline_us();
    const std::int64_t wait_us = std::clamp<std::int64_t>(deadline - now, 0, 100'000);
    pollfd pfd{bus.fd(), POLLIN, 0};
    const int rc = ::poll(&pfd, 1, static_cast<int>((wait_us + 999) / 1000));
    if (rc < 0 && errno != EINTR) {
      std::perror("loom-sim-drive: poll");
      return 1;
    }
    rack.step(monotonic_us());
    if (verbose) {
      for (std::size_t i = 0; i < rack.size(); ++i) {
        const auto& n = rack.node(i);
        const std::pair now_state{n.nmt_state(), n.drive_state()};
        if (now_state != shown[i]) {
          shown[i] = now_state;
          std::cerr << "loom-sim-drive: node " << int{n.node_id()} << ": NMT "
                    << loom::drivers::nmt_state_name(n.nmt_state()) << ", drive "
                    << loom::hal::drive_state_name(n.drive_state()) << ", position " << n.position() << "\n";
        }
      }
    }
  }
  std::cerr << "loom-sim-drive: stopped\n";
  return 0;
}
