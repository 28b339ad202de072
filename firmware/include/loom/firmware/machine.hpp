// Assembles one loom from a config and a scene: profiles, sequencer, the chosen HAL (simulated, or CAN
// drives with the simulated I/O node until the real one is wired), telemetry, and the control loop.
// Everything here is configure-time; the pieces it returns are what the RT loop runs.
#pragma once

#include <memory>
#include <string>

#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/socket_can_bus.hpp"
#include "loom/firmware/config.hpp"
#include "loom/firmware/control_loop.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/motion/profile_slot.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/sim_world.hpp"
#include "loom/telemetry/telemetry.hpp"

namespace loom::firmware {

enum class HalKind { kSim, kSocketCan };

struct MachineOptions {
  HalKind hal = HalKind::kSim;
  std::string iface;             // SocketCAN interface for kSocketCan
  bool telemetry = true;
  bool lossless_telemetry = true;  // virtual time only: wait for ring space instead of dropping
  std::uint32_t rows = 3;
  std::string sim_state_path;  // sim HAL: keep the simulated machine's physical state here (power-loss tests)
};

class Machine {
 public:
  // Throws ConfigError on bad input, std::runtime_error when the hardware cannot be armed (the message
  // names interface, node and step).
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
  const drivers::CanAxisPort* can() const { return can_port_.get(); }
  const sim_hal::SimWorld& sim() const { return *sim_; }
  sim_hal::SimWorld& sim() { return *sim_; }  // configure-time: e.g. a power-cut handler for in-process runs
  const LoomConfig& config() const { return cfg_; }

 private:
  LoomConfig cfg_;
  std::unique_ptr<motion::ProfileSlot> slot_;
  std::unique_ptr<sequencer::Sequencer> sequencer_;
  std::unique_ptr<sim_hal::SimStateFile> sim_state_;
  std::unique_ptr<sim_hal::SimWorld> sim_;
  std::unique_ptr<drivers::SocketCanBus> bus_;
  std::unique_ptr<drivers::CanAxisPort> can_port_;
  std::unique_ptr<hal::PortHal> hal_;
  std::unique_ptr<telemetry::Telemetry> telemetry_;
  std::unique_ptr<ControlLoop> loop_;
};

}  // namespace loom::firmware
