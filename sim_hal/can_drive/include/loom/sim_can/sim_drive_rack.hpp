// Several simulated drives sharing one CAN endpoint, as in the loom-sim-drive process: every received
// frame is offered to every node (each filters its own), then their timers run. Injected time only.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "loom/sim_can/sim_drive_node.hpp"

namespace loom::sim_can {

class SimDriveRack {
 public:
  // Configure-time only.
  SimDriveRack(drivers::CanBus& bus, const std::vector<SimDriveConfig>& nodes);

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
};

}  // namespace loom::sim_can
