// The ring-plus-publisher facade the firmware holds (see telemetry.hpp).
#include "loom/telemetry/telemetry.hpp"

#include <thread>

namespace loom::telemetry {

Telemetry::Telemetry(const PublisherConfig& cfg)
    : ring_(std::make_unique<SnapshotRing>()),
      events_(std::make_unique<EventRing>()),
      publisher_(cfg, *ring_, *events_) {}

bool Telemetry::push_waiting(const Snapshot& s) noexcept {
  while (!ring_->try_push(s, copy_in_use)) {
    if (!publisher_.running()) return ring_->push_or_drop(s, copy_in_use);
    std::this_thread::yield();
  }
  return true;
}

bool Telemetry::push_event_waiting(const Event& e) noexcept {
  while (!events_->try_push(e)) {
    if (!publisher_.running()) return events_->push_or_drop(e);
    std::this_thread::yield();
  }
  return true;
}

}  // namespace loom::telemetry
