// Assembles one loom from a config and a scene: profiles, sequencer, the chosen HAL (simulated, or CAN
// drives with the simulated I/O node until the real one is wired), telemetry, and the control loop.
// Everything here is configure-time; the pieces it returns are what the RT loop runs.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/can_hal.hpp"
#include "loom/drivers/can_io_modules.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/can_network.hpp"
#include "loom/drivers/socket_can_bus.hpp"
#include "loom/firmware/control_loop.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/motion/profile_slot.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/sim_world.hpp"
#include "loom/telemetry/telemetry.hpp"

namespace loom::firmware {

enum class HalKind { kSim, kSocketCan };
class SimWeaver;

struct MachineOptions {
  HalKind hal = HalKind::kSim;
  std::string iface;  // SocketCAN interface(s) for kSocketCan: "can0" or "can0,can1" (bus i = i-th)
  bool telemetry = true;
  bool lossless_telemetry = true;  // virtual time only: wait for ring space instead of dropping
  std::uint32_t rows = 3;
  // A counters file is kept: each row waits until the one before it is on disk (RunOptions::row_saves).
  bool await_row_saved = false;
  std::string sim_state_path;  // sim HAL: keep the simulated machine's physical state here (power-loss tests)
  // `--io`: overrides the config's io.kind. Real drives with simulated I/O only when this says
  // kSimulated explicitly (the config alone is not enough), and then banner() is set.
  std::optional<IoKind> io;
  // The recipe's design: rows of it woven before this session (from the design book), so DESIGN
  // telemetry shows the weaver the right row to knot next.
  std::uint64_t design_rows_done = 0;
  // A carpet job's first production row: the simulated carpet kept in the sim-state file is this job's
  // only if it began there or later (the carpet before it was cut off; `job start-over` starts another).
  std::optional<std::uint32_t> carpet_began;
};

// Printed on every start when real drives run beside simulated I/O.
inline constexpr const char* kSimulatedIoBanner =
    "SIMULATED I/O: the e-stop chain, end sensors, shuttle sensors, valves and load cell are simulated; "
    "the interlocks are not protecting anything on this machine";

class Machine {
 public:
  // Throws ConfigError on bad input (including real drives with simulated I/O not asked for on the
  // command line, refused before the bus is opened), std::runtime_error when the hardware cannot be
  // armed (the message names interface, node and step).
  Machine(const LoomConfig& cfg, const Scene& scene, const MachineOptions& opt, sequencer::Counters resume);
  ~Machine();

  ControlLoop& loop() { return *loop_; }
  sequencer::Sequencer& sequencer() { return *sequencer_; }
  // The recipe the loop started with (the sequencer's current one is sequencer().profiles()).
  const motion::ProfileSet& profiles() const { return sequencer_->profiles(); }
  // Non-RT. Build the profiles of `next` and hand them to the running loop, which adopts them at the
  // next row boundary. Throws ConfigError when `next` changes something only a restart can change
  // (period, HAL settings, loom id) or its motion cannot be built; the running recipe is untouched.
  void publish_recipe(const LoomConfig& next);
  // Non-RT. Free a recipe the loop has retired. Call now and then (after each row is enough).
  void collect_retired_recipes() { slot_->collect(); }
  telemetry::Telemetry* telemetry() { return telemetry_.get(); }
  // Non-empty when the caller must print it on every start (kSimulatedIoBanner).
  const std::string& banner() const { return banner_; }
  // What bring-up found optional and absent or accepted as read back (0x1016, fixed mappings), and the
  // bus load and bitrate check; one line each, for the start-up log.
  const std::vector<std::string>& notes() const { return notes_; }
  const sim_hal::SimWorld& sim() const { return *sim_; }
  sim_hal::SimWorld& sim() { return *sim_; }  // configure-time: e.g. a power-cut handler for in-process runs
  const LoomConfig& config() const { return cfg_; }
  // RT-safe. The loom asks the weaver: with the simulated machine's knotter the simulated weaver answers
  // (`machine` is this Machine: for in-process tests that step the sequencer themselves).
  static void simulated_weaver_sink(void* machine, const sequencer::WeaverRequest& r) noexcept;
  // The simulated weaver (null on hardware): what Session gives the runner, in weave and serve alike.
  SimWeaver* sim_weaver() const { return sim_weaver_.get(); }
  // The design as the knotting heads tie it (null without heads).
  const sequencer::KnotProgram* knot_program() const { return knot_program_.get(); }
  const motion::KnotCycle* knot_cycle() const { return knot_cycle_.get(); }  // null without heads

 private:
  void build_knotting(const MachineOptions& opt, std::uint32_t counter_rows,
                      sequencer::SequencerConfig& scfg);
  void build_can_hal(const MachineOptions& opt);

  LoomConfig cfg_;
  std::unique_ptr<motion::ProfileSlot> slot_;
  std::unique_ptr<const sequencer::KnotProgram> knot_program_;  // the design as magazine slots (heads)
  std::unique_ptr<const motion::KnotCycle> knot_cycle_;         // the knotting servo's cycle (heads)
  std::unique_ptr<sequencer::Sequencer> sequencer_;
  std::unique_ptr<sim_hal::SimStateFile> sim_state_;
  std::unique_ptr<sim_hal::SimWorld> sim_;
  std::unique_ptr<SimWeaver> sim_weaver_;                      // the simulated HAL only
  std::vector<std::unique_ptr<drivers::SocketCanBus>> buses_;  // bus i = the i-th --iface name
  std::unique_ptr<drivers::CanNetwork> network_;  // the masters, one per bus; the ports are views on it
  std::unique_ptr<drivers::CanAxisPort> can_port_;
  std::vector<std::unique_ptr<drivers::CanIoPort>> io_modules_;  // module k = can_io_configs()[k]
  std::unique_ptr<drivers::CanIoModules> io_port_;               // the modules as the loop's one I/O port
  std::string banner_;
  std::vector<std::string> notes_;
  std::unique_ptr<hal::Hal> hal_;  // the simulated ports, or the CAN network and its ports
  std::unique_ptr<telemetry::Telemetry> telemetry_;
  std::unique_ptr<ControlLoop> loop_;
};

}  // namespace loom::firmware
