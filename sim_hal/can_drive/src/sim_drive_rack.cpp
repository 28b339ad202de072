// Several simulated drives behind one CAN endpoint (see sim_drive_rack.hpp).
#include "loom/sim_can/sim_drive_rack.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace loom::sim_can {

SimDriveRack::SimDriveRack(drivers::CanBus& bus, const std::vector<SimDriveConfig>& nodes) : bus_(bus) {
  for (const SimDriveConfig& c : nodes) nodes_.push_back(std::make_unique<SimDriveNode>(bus_, c));
}

void SimDriveRack::attach_io(SimIoNode& io, IoPlantSource source) {
  // Attaching a node again only changes the source (a test re-points the plant at other drives).
  if (std::find(io_.begin(), io_.end(), &io) == io_.end()) io_.push_back(&io);
  io_source_ = std::move(source);
}

void SimDriveRack::power_on(std::int64_t now_us) {
  for (auto& n : nodes_) n->power_on(now_us);
  for (SimIoNode* io : io_) io->power_on(now_us);
}

void SimDriveRack::step(std::int64_t now_us, int max_frames) {
  drivers::CanFrame f;
  int drained = 0;
  for (; drained < max_frames && bus_.receive(f); ++drained) {
    for (auto& n : nodes_) n->handle(f, now_us);
    for (SimIoNode* io : io_) io->handle(f, now_us);
  }
  // A backlog (this process was descheduled) is worked off before any timer runs: a heartbeat the
  // master sent long ago but we have not read yet must not look like the master's silence.
  if (drained == max_frames) return;
  for (auto& n : nodes_) n->step(now_us);
  if (!io_.empty()) {
    IoPlant p = io_controls_;
    if (io_source_.crank < nodes_.size()) {
      p.crank_rad =
          static_cast<double>(nodes_[io_source_.crank]->position()) / io_source_.crank_counts_per_rad;
    }
    if (io_source_.helix < nodes_.size()) {
      p.helix_rad =
          static_cast<double>(nodes_[io_source_.helix]->position()) / io_source_.helix_counts_per_rad;
    }
    for (const IoPlantSource::Axis& a : io_source_.axes) {
      if (a.node < nodes_.size() && a.slot < p.axis_position.size()) {
        p.axis_position[a.slot] = static_cast<double>(nodes_[a.node]->position()) / a.counts_per_unit;
      }
    }
    for (SimIoNode* io : io_) io->step(now_us, p);
  }
}

std::int64_t SimDriveRack::next_deadline_us() const {
  std::int64_t t = std::numeric_limits<std::int64_t>::max();
  for (const auto& n : nodes_) t = std::min(t, n->next_deadline_us());
  for (const SimIoNode* io : io_) t = std::min(t, io->next_deadline_us());
  return t;
}

}  // namespace loom::sim_can
