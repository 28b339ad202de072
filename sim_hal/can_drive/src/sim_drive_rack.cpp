// Several simulated drives behind one CAN endpoint (see sim_drive_rack.hpp).
#include "loom/sim_can/sim_drive_rack.hpp"

#include <algorithm>
#include <limits>

namespace loom::sim_can {

SimDriveRack::SimDriveRack(drivers::CanBus& bus, const std::vector<SimDriveConfig>& nodes) : bus_(bus) {
  for (const SimDriveConfig& c : nodes) nodes_.push_back(std::make_unique<SimDriveNode>(bus_, c));
}

void SimDriveRack::power_on(std::int64_t now_us) {
  for (auto& n : nodes_) n->power_on(now_us);
}

void SimDriveRack::step(std::int64_t now_us, int max_frames) {
  drivers::CanFrame f;
  for (int i = 0; i < max_frames && bus_.receive(f); ++i) {
    for (auto& n : nodes_) n->handle(f, now_us);
  }
  for (auto& n : nodes_) n->step(now_us);
}

std::int64_t SimDriveRack::next_deadline_us() const {
  std::int64_t t = std::numeric_limits<std::int64_t>::max();
  for (const auto& n : nodes_) t = std::min(t, n->next_deadline_us());
  return t;
}

}  // namespace loom::sim_can
