// loom-sim-drive: simulated CiA 402 servo drives and (optionally) the loom's CiA 401 I/O node on a (v)CAN
// interface, so the firmware's CANopen master can be tested end to end without hardware. Runs until
// SIGINT/SIGTERM; bad arguments exit 2.
//   loom-sim-drive --iface vcan0 --nodes 1,2,3 [--io-node 4] [--personality standard|fixed]
//                  [--counts-per-unit A,B,C] [--initial-position a,b,c] [--io-control FILE]
//                  [--homing-nodes 1,2 [--power-up-seed N]]
//   loom-sim-drive --iface vcan0 --nodes 1,2,3 --eds VENDOR.eds   (every drive as the EDS describes it)
//   loom-sim-drive ... --io-node 4 --io-eds MODULE.eds               (the I/O module as its EDS describes it)
//   loom-sim-drive --iface vcan0 --loom LOOM.toml [--bus N] [--io-control FILE] ...
// --loom: the nodes of bus N (default 0) as the machine description has them — drives in axis-slot order
// with their scaling and referencing, the I/O modules on that bus (io.kind = "can": the [io] one on bus 0,
// each [io_modules.<name>] on its bus) with the loom's width and helix lead — and, for a loom with knotting
// heads, the heads behind the module their grippers are wired to (grippers, cutters, yarn-present switches,
// each head's magazine; the carriage and every head's servos must then be on this bus). Every module
// simulates the whole plant on the terminals of the default wiring; the master reads and writes the ones
// the machine description puts on it.
// --homing-nodes: those drives have incremental encoders: they offer CiA 402 homing (mode 6; methods 19/21
// on a home switch at physical 0, 33/34 on an index pulse every 4096 counts, 37 where they stand) and
// power up at a random count (the seed is printed; give it back to reproduce a run).
// The I/O node's pistons follow its valve outputs, its shuttle sensors the helix drive (3rd node), its
// load cell the crank drive (1st node). --io-control FILE is re-read when it changes: whitespace-separated
// words estop, start, pause, ack, knotted, silent, stuck=<sensor>[_2]:on|off (present = active; the last
// sticks one switch of a safety sensor, `_2` its second, e.g. stuck=shuttle_at_right_2:on), for HIL
// fault tests; io_control.hpp describes them.
#include <poll.h>
#include <sys/stat.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <deque>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/socket_can_bus.hpp"
#include "loom/sim_can/eds_dictionary.hpp"
#include "loom/sim_can/io_control.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"
#include "loom/sim_heads/sim_heads.hpp"

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

// The simulated nodes answer a burst of SYNCs (after this process was descheduled) with a burst of
// frames; the socket's transmit queue then overflows. A real node's CAN controller queues and retries,
// so this one does too: frames the socket refuses wait here, in order, and go out first next time.
class RetryingBus final : public loom::drivers::CanBus {
 public:
  explicit RetryingBus(loom::drivers::CanBus& inner) : inner_(inner) {}
  loom::drivers::SendResult send(const loom::drivers::CanFrame& f) noexcept override {
    flush();
    if (pending_.empty() && inner_.send(f) == loom::drivers::SendResult::kOk)
      return loom::drivers::SendResult::kOk;
    if (pending_.size() < 4096) pending_.push_back(f);
    return loom::drivers::SendResult::kOk;
  }
  bool receive(loom::drivers::CanFrame& f) noexcept override { return inner_.receive(f); }
  void flush() {
    while (!pending_.empty() && inner_.send(pending_.front()) == loom::drivers::SendResult::kOk)
      pending_.pop_front();
  }
  bool pending() const { return !pending_.empty(); }

 private:
  loom::drivers::CanBus& inner_;
  std::deque<loom::drivers::CanFrame> pending_;
};

// Default scaling of the loom's axes by node position: crank and helix in counts/rad, carriage in
// counts/m (same defaults as the master's CanAxisPortConfig).
double default_counts_per_unit(std::size_t i) {
  return i == 1 ? loom::drivers::kDefaultCountsPerM : loom::drivers::kDefaultCountsPerRad;
}

// The carpet the simulated heads knotted, one line per row (the magazine slot of each knot, '.' none, a
// digit per knot tied more than once: a defect), for the HIL test to compare with the design.
void print_carpet(const loom::sim_hal::SimKnotter& k) {
  for (int r = 0; r < k.rows(); ++r) {
    std::string line;
    for (int j = 0; j < k.knots_per_row(); ++j) {
      const loom::sim_hal::KnotCell& c = k.cell(r, j);
      line += c.ties == 0  ? '.'
              : c.ties > 1 ? static_cast<char>('0' + std::min<int>(c.ties, 9))
                           : static_cast<char>('A' + c.slot);
    }
    std::cerr << "loom-sim-drive: knotted row " << r << ": " << line << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulated CiA 402 servo drives (CSP) on a CAN interface"};
  std::string iface;
  std::vector<int> nodes{1, 2, 3};
  std::vector<double> counts_per_unit;
  std::vector<double> initial_position;
  std::uint32_t max_step_counts = 0;
  double plant_cycle_ms = 0.0;
  bool verbose = false;
  int io_node = 0;
  std::string personality = "standard";
  std::string io_control;
  double boot_delay_ms = -1.0, operational_delay_ms = -1.0;
  double width_m = 0.6, helix_lead_m = 0.1;
  std::vector<int> homing_nodes;
  std::uint64_t power_up_seed = 0;
  std::string loom_file;
  int loom_bus = 0;
  std::string eds_file, io_eds_file;
  app.add_option("--iface", iface, "CAN interface, e.g. vcan0")->required();
  auto* loom_opt =
      app.add_option("--loom", loom_file,
                     "the machine description: simulate bus --bus's drives and (bus 0) its I/O node with "
                     "the loom's facts, knotting heads included");
  app.add_option("--bus", loom_bus, "with --loom: which of the loom's buses this interface is (default 0)")
      ->check(CLI::Range(0, 15))
      ->needs(loom_opt);
  auto* io_node_opt =
      app.add_option("--io-node", io_node, "also simulate the CiA 401 I/O node with this node id (1..127)");
  app.add_option(
      "--io-control", io_control,
      "file of words for the I/O node, re-read when it changes: estop start pause ack knotted silent, "
      "stuck=<sensor>[_2]:on|off (one switch of a safety sensor stuck, _2 = its second switch, e.g. "
      "stuck=shuttle_at_right_2:on)");
  auto* width_opt =
      app.add_option("--width-m", width_m, "loom width for the I/O node's shuttle sensors (default 0.6)");
  auto* lead_opt = app.add_option("--helix-lead-m", helix_lead_m,
                                  "helix lead for the I/O node's shuttle sensors (default 0.1)");
  app.add_option("--personality", personality,
                 "standard | fixed (read-only PDO mappings, no TPDO3/4, no 0x1016, slow boot and start)")
      ->check(CLI::IsMember({"standard", "fixed"}));
  app.add_option("--eds", eds_file,
                 "build every drive's object dictionary from this CiA 306 EDS: its objects, access, fixed or "
                 "dynamic PDO mapping, PDO count, supported modes (0x6502) and identity (0x1018)")
      ->excludes("--personality");
  app.add_option("--io-eds", io_eds_file,
                 "build the I/O module's object dictionary from this CiA 306 EDS: its objects, access, PDO "
                 "mapping, identity and input groups (0x6000 8-bit and/or 0x6100 16-bit)")
      ->needs(io_node_opt);
  app.add_option("--boot-delay-ms", boot_delay_ms, "boot-up delay (default 0; fixed personality 300)");
  app.add_option("--operational-delay-ms", operational_delay_ms,
                 "NMT start → operational delay (default 0; fixed personality 400)");
  auto* nodes_opt = app.add_option("--nodes", nodes, "node ids, comma separated (1..127)")->delimiter(',');
  auto* cpu_opt =
      app.add_option("--counts-per-unit", counts_per_unit,
                     "counts per SI unit per node (rad or m); default 2^20/2π, 2^20/0.01 m, 2^20/2π")
          ->delimiter(',');
  app.add_option("--initial-position", initial_position, "initial position per node in SI units")
      ->delimiter(',');
  app.add_option("--plant-cycle-ms", plant_cycle_ms,
                 "I/O node plant: advance this much machine time per SYNC (0 = wall clock)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--max-step-counts", max_step_counts,
                 "largest target step per SYNC before a following-error fault (0 = off)");
  auto* homing_opt =
      app.add_option(
             "--homing-nodes", homing_nodes,
             "drives with an incremental encoder: CiA 402 homing offered, a random count at every power-up")
          ->delimiter(',');
  // The machine description says these; giving both would be two sources for one fact.
  for (CLI::Option* o : {nodes_opt, cpu_opt, io_node_opt, width_opt, lead_opt, homing_opt})
    o->excludes(loom_opt);
  app.add_option("--power-up-seed", power_up_seed,
                 "seed of the random power-up counts (default: chosen, printed)");
  app.add_flag("--verbose", verbose, "print NMT and drive state changes");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return usage_error(e.what());
  }

  // --loom: the bus's nodes and the plant's facts from the machine description.
  std::vector<std::size_t> slot_of_node;  // loom axis slot of each simulated drive (--loom only)
  std::unique_ptr<loom::firmware::SimHeads> heads;
  std::vector<int> io_nodes;  // the I/O modules simulated here (--io-node, or --loom's on this bus)
  int heads_io_node = 0;      // the one the knotting heads are behind (0: none here)
  if (!loom_file.empty()) {
    try {
      const loom::firmware::LoomConfig cfg = loom::firmware::load_loom_config(loom_file);
      nodes.clear();
      for (std::size_t slot = 0; slot < cfg.axes.size(); ++slot) {
        const loom::firmware::AxisSpec& a = cfg.axes[slot];
        if (a.bus != loom_bus) continue;
        nodes.push_back(a.node);
        counts_per_unit.push_back(a.counts_per_unit());
        slot_of_node.push_back(slot);
        if (a.homing) homing_nodes.push_back(a.node);
      }
      if (cfg.io.kind == loom::firmware::IoKind::kCan) {
        const std::vector<loom::drivers::CanIoConfig> modules = loom::firmware::can_io_configs(cfg);
        const std::vector<std::size_t> buses = loom::firmware::can_io_buses(cfg);
        for (std::size_t k = 0; k < modules.size(); ++k) {
          if (buses[k] != static_cast<std::size_t>(loom_bus)) continue;
          io_nodes.push_back(modules[k].node_id);
          if (cfg.knotting.mode == loom::sequencer::KnottingMode::kHeads &&
              cfg.io.gripper_close.module == k) {
            heads_io_node = modules[k].node_id;
          }
        }
      }
      width_m = cfg.machine_spec.width_m;
      helix_lead_m = cfg.machine_spec.helix_lead_m;
      if (heads_io_node != 0) {
        heads = std::make_unique<loom::firmware::SimHeads>(loom::firmware::sim_heads(cfg));
        const loom::sim_hal::SimKnotting& k = heads->knotting;
        std::vector<std::size_t> needed{
            static_cast<std::size_t>(loom::hal::index(loom::hal::CoreAxis::kCarriage))};
        for (int h = 0; h < k.heads; ++h) {
          needed.push_back(k.knotter_axis[static_cast<std::size_t>(h)]);
          needed.push_back(k.selector_axis[static_cast<std::size_t>(h)]);
        }
        for (std::size_t slot : needed) {
          if (cfg.axes[slot].bus != loom_bus) {
            return usage_error("--loom " + loom_file + ": axes." + cfg.axes[slot].name + " is on bus " +
                               std::to_string(cfg.axes[slot].bus) +
                               "; the simulated knotting heads behind the I/O "
                               "node follow the carriage and every head's servos, so they must be on bus " +
                               std::to_string(loom_bus) + " with it");
          }
        }
      }
    } catch (const std::exception& e) {
      std::cerr << "loom-sim-drive: " << e.what() << "\n";
      return 2;
    }
    if (nodes.empty() && io_nodes.empty()) {
      return usage_error("--loom " + loom_file + ": no axis and no I/O module is on bus " +
                         std::to_string(loom_bus));
    }
  } else if (io_node != 0) {
    io_nodes.push_back(io_node);
  }

  std::set<int> seen;
  for (int n : nodes) {
    if (n < 1 || n > 127) return usage_error("--nodes: node id " + std::to_string(n) + " is outside 1..127");
    if (!seen.insert(n).second) return usage_error("--nodes: node id " + std::to_string(n) + " given twice");
  }
  if (nodes.empty() && io_nodes.empty()) return usage_error("--nodes: at least one node id is needed");
  if (io_node != 0 && (io_node < 1 || io_node > 127)) {
    return usage_error("--io-node: node id " + std::to_string(io_node) + " is outside 1..127");
  }
  if (io_node != 0 && seen.count(io_node) != 0) {
    return usage_error("--io-node: node id " + std::to_string(io_node) + " is already a drive in --nodes");
  }
  const bool fixed = personality == "fixed";
  if (boot_delay_ms < 0.0) boot_delay_ms = fixed ? 300.0 : 0.0;
  if (operational_delay_ms < 0.0) operational_delay_ms = fixed ? 400.0 : 0.0;
  if (boot_delay_ms > 60000.0 || operational_delay_ms > 60000.0) {
    return usage_error("--boot-delay-ms / --operational-delay-ms: at most 60000");
  }
  if (!(width_m > 0.0) || !(helix_lead_m > 0.0)) return usage_error("--width-m / --helix-lead-m must be > 0");
  if (!counts_per_unit.empty() && counts_per_unit.size() != nodes.size()) {
    return usage_error("--counts-per-unit: " + std::to_string(counts_per_unit.size()) + " values for " +
                       std::to_string(nodes.size()) + " nodes");
  }
  if (!initial_position.empty() && initial_position.size() != nodes.size()) {
    return usage_error("--initial-position: " + std::to_string(initial_position.size()) + " values for " +
                       std::to_string(nodes.size()) + " nodes");
  }
  for (int n : homing_nodes) {
    if (seen.count(n) == 0)
      return usage_error("--homing-nodes: node id " + std::to_string(n) + " is not in --nodes");
  }
  if (!homing_nodes.empty()) {
    if (power_up_seed == 0) power_up_seed = (static_cast<std::uint64_t>(std::random_device{}()) << 1) | 1U;
    std::fprintf(stderr, "loom-sim-drive: power-up seed %llu (--power-up-seed to repeat)\n",
                 static_cast<unsigned long long>(power_up_seed));
  }
  loom::drivers::eds::Description description;
  if (!eds_file.empty()) {
    description = loom::drivers::eds::read_eds_file(eds_file);
    for (const loom::drivers::eds::Diagnostic& d : description.diagnostics) {
      std::cerr << "loom-sim-drive: " << loom::drivers::eds::format(description.file, d) << "\n";
    }
    if (description.has_errors()) return 2;
  }
  loom::drivers::eds::Description io_description;
  if (!io_eds_file.empty()) {
    io_description = loom::drivers::eds::read_eds_file(io_eds_file);
    for (const loom::drivers::eds::Diagnostic& d : io_description.diagnostics) {
      std::cerr << "loom-sim-drive: " << loom::drivers::eds::format(io_description.file, d) << "\n";
    }
    if (io_description.has_errors()) return 2;
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
    c.boot_delay_us = static_cast<std::int64_t>(boot_delay_ms * 1000.0);
    c.operational_delay_us = static_cast<std::int64_t>(operational_delay_ms * 1000.0);
    if (std::find(homing_nodes.begin(), homing_nodes.end(), nodes[i]) != homing_nodes.end()) {
      c.supports_homing = true;
      c.power_up_seed = power_up_seed + 2 * i;  // odd seeds stay non-zero
    }
    if (fixed) {
      c.fixed_mapping = true;
      c.missing_objects = {0x1802, 0x1803, 0x1A02, 0x1A03, 0x1016};
    }
    if (!eds_file.empty()) {
      loom::sim_can::SimDriveConfig described = loom::sim_can::drive_from_eds(description, c.node_id);
      c.dictionary = std::move(described.dictionary);
      c.supports_csp = described.supports_csp;
    }
    configs.push_back(c);
  }

  auto opened = loom::drivers::SocketCanBus::open(iface);
  if (!opened) {
    std::cerr << "loom-sim-drive: " << opened.error() << "\n";
    return 1;
  }
  loom::drivers::SocketCanBus& socket_bus = *opened.value();
  RetryingBus bus(socket_bus);

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  loom::sim_can::SimDriveRack rack(bus, configs);
  std::vector<std::unique_ptr<loom::sim_can::SimIoNode>> ios;
  for (int n : io_nodes) {
    loom::sim_can::SimIoConfig ic;
    if (!io_eds_file.empty()) ic = loom::sim_can::io_from_eds(io_description, static_cast<std::uint8_t>(n));
    ic.node_id = static_cast<std::uint8_t>(n);
    ic.width_m = width_m;
    ic.helix_lead_m = helix_lead_m;
    ic.plant_cycle_s = plant_cycle_ms * 1e-3;
    if (heads && n == heads_io_node) ic.knotting = heads->knotting;
    ios.push_back(std::make_unique<loom::sim_can::SimIoNode>(bus, ic));
    // The crank (1st) and helix (3rd) drives by rack position; with --loom, where the loom's slots 0 and 2
    // are on this bus (a position past the rack: that shaft is on another bus, its sensors read rest).
    std::size_t crank = 0, helix = 2;
    if (!loom_file.empty()) {
      const auto at = [&](std::size_t slot) {
        return static_cast<std::size_t>(std::find(slot_of_node.begin(), slot_of_node.end(), slot) -
                                        slot_of_node.begin());
      };
      crank = at(0);
      helix = at(2);
    }
    const auto cpr = [&](std::size_t i) {
      return i < counts_per_unit.size() ? counts_per_unit[i] : default_counts_per_unit(i);
    };
    loom::sim_can::SimDriveRack::IoPlantSource source{crank, helix, cpr(crank), cpr(helix), {}};
    for (std::size_t i = 0; i < slot_of_node.size(); ++i) {  // every drive's position, by the loom's slot
      source.axes.push_back({i, slot_of_node[i], counts_per_unit[i]});
    }
    rack.attach_io(*ios.back(), source);
  }
  // The control file (HIL fault tests): re-read when its modification time changes.
  timespec control_mtime{};
  const auto read_control = [&] {
    if (io_control.empty()) return;
    struct stat st {};
    if (::stat(io_control.c_str(), &st) != 0) return;
    if (st.st_mtim.tv_sec == control_mtime.tv_sec && st.st_mtim.tv_nsec == control_mtime.tv_nsec) return;
    control_mtime = st.st_mtim;
    std::ifstream in(io_control);
    std::stringstream words;
    words << in.rdbuf();
    for (const std::string& ignored : loom::sim_can::set_io_controls(words.str(), rack.io_controls())) {
      std::cerr << "loom-sim-drive: --io-control: " << ignored << "\n";
    }
    // One line per re-read (HIL tests wait for it), also for an empty file or a last word without newline.
    std::string applied = words.str();
    while (!applied.empty() && std::isspace(static_cast<unsigned char>(applied.back())) != 0)
      applied.pop_back();
    std::cerr << "loom-sim-drive: I/O controls now: " << applied << "\n";
  };
  rack.power_on(monotonic_us());
  std::cerr << "loom-sim-drive: " << nodes.size() << " " << personality << " drive(s) on " << iface
            << ", nodes";
  for (int n : nodes) std::cerr << ' ' << n;
  for (int n : io_nodes) std::cerr << ", I/O node " << n;
  std::cerr << std::endl;
  std::int64_t next_control_check = 0;

  std::vector<std::pair<loom::drivers::NmtState, loom::hal::DriveState>> shown(rack.size());
  while (g_stop == 0) {
    const std::int64_t now = monotonic_us();
    const std::int64_t deadline = rack.next_deadline_us();
    // Frames waiting for the transmit queue are retried every millisecond.
    const std::int64_t wait_us = std::clamp<std::int64_t>(deadline - now, 0, bus.pending() ? 1'000 : 100'000);
    pollfd pfd{socket_bus.fd(), POLLIN, 0};
    const int rc = ::poll(&pfd, 1, static_cast<int>((wait_us + 999) / 1000));
    if (rc < 0 && errno != EINTR) {
      std::perror("loom-sim-drive: poll");
      return 1;
    }
    const std::int64_t t = monotonic_us();
    if (t >= next_control_check) {
      read_control();
      next_control_check = t + 20'000;
    }
    bus.flush();
    rack.step(t);
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
  for (const auto& io : ios) {
    if (io->knotter() != nullptr) print_carpet(*io->knotter());
  }
  std::cerr << "loom-sim-drive: stopped\n";
  return 0;
}
