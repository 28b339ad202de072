// The ring-plus-publisher facade the firmware holds (see telemetry.hpp).
#include "loom/telemetry/telemetry.hpp"

#include <thread>

namespace loom::telemetry {

Telemetry::Telemetry(const PublisherConfig& cfg)
    : ring_(std::make_unique<SnapshotRing>()), publisher_(cfg, *ring_) {}

bool Telemetry::push_waiting(const Snapshot& s) noexcept {
  while (!ring_->try_push(s)) {
    if (!publisher_.running()) return ring_->push_or_drop(s);
    std::this_thread::yield();
  }
  return true;
}

}  // namespace loom::telemetry
