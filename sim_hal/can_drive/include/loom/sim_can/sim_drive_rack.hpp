// Several simulated drives sharing one CAN endpoint, as in the loom-sim-drive process: every received
// frame is offered to every node (each filters its own), then their timers run. Injected time only.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "loom/sim_can/sim_drive_node.hpp"
#include "loom/sim_can/sim_io_node.hpp"

namespace loom::sim_can {

class SimDriveRack {
 public:
  // Configure-time only.
  SimDriveRack(drivers::CanBus& bus, const std::vector<SimDriveConfig>& nodes);

  // Configure-time only. An I/O node on the same endpoint, whose plant follows the drives at rack
  // positions `crank` and `helix` (counts → rad with their counts per rad; a position past the rack's
  // drives: that shaft is not on this bus). A loom with several I/O modules on one bus attaches each
  // (the same source: one machine behind them).
  struct IoPlantSource {
    std::size_t crank = 0;
    std::size_t helix = 2;
    double crank_counts_per_rad = 1.0;
    double helix_counts_per_rad = 1.0;
    // The drives whose positions the knotting heads' plant reads (IoPlant::axis_position): rack position
    // `node`, loom axis slot `slot`, counts per SI unit.
    struct Axis {
      std::size_t node = 0;
      std::size_t slot = 0;
      double counts_per_unit = 1.0;
    };
    std::vector<Axis> axes{};
  };
  void attach_io(SimIoNode& io, IoPlantSource source);
  // The e-stop, buttons, "silent" switch and stuck safety switch (IoPlant::stuck) the I/O node sees
  // (tests and the control file set them); step() hands them to the node with the drives' positions.
  IoPlant& io_controls() { return io_controls_; }

  void power_on(std::int64_t now_us);  // RT-safe
  // RT-safe. Drain up to `max_frames` received frames into the nodes, then step their timers.
  void step(std::int64_t now_us, int max_frames = 1024);
  std::int64_t next_deadline_us() const;  // RT-safe

  std::size_t size() const { return nodes_.size(); }
  SimDriveNode& node(std::size_t i) { return *nodes_[i]; }
  const SimDriveNode& node(std::size_t i) const { return *nodes_[i]; }

 private:
  drivers::CanBus& bus_;
  std::vector<std::unique_ptr<SimDriveNode>> nodes_;
  std::vector<SimIoNode*> io_;
  IoPlantSource io_source_{};
  IoPlant io_controls_{};
};

}  // namespace loom::sim_can
