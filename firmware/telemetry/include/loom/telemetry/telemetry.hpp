// The one telemetry object the firmware holds: the snapshot ring plus its publisher. The RT loop only
// ever calls push(); construction, start and stop belong to configure/shutdown.
#pragma once

#include <cstdint>
#include <memory>

#include "loom/telemetry/publisher.hpp"
#include "loom/telemetry/snapshot.hpp"

namespace loom::telemetry {

class Telemetry {
 public:
  // Configure-time only. Allocates and pre-touches the ring, opens LCM; throws std::invalid_argument
  // on a bad config or an LCM URL that will not open (message names the field and value).
  explicit Telemetry(const PublisherConfig& cfg);
  ~Telemetry() { publisher_.stop(); }  // the publisher reads both rings: stop it before they go

  // Configure-time only.
  void start() { publisher_.start(); }
  // Non-RT. Publishes what is left in the ring, then joins the publishing thread.
  void stop() { publisher_.stop(); }

  // RT-safe. Copies the snapshot (the part in use: copy_in_use) into the ring; when the ring is full
  // the snapshot is dropped, counted in dropped(), and false is returned. Never blocks, never allocates.
  bool push(const Snapshot& s) noexcept { return ring_->push_or_drop(s, copy_in_use); }

  // RT-safe. Like push() but a full ring is not counted as a drop: for a caller that will retry
  // (virtual-time simulation, where the loop may wait for the publisher so nothing is lost).
  bool try_push(const Snapshot& s) noexcept { return ring_->try_push(s, copy_in_use); }

  // NOT RT-safe: virtual time only. Retries (yielding the CPU) until the ring takes the snapshot;
  // gives up and counts a drop if the publisher is not running, since then nobody would make room.
  bool push_waiting(const Snapshot& s) noexcept;

  // RT-safe. Queues an event (BEAT, FAULT, ROW) on the event ring, which is separate from the
  // snapshot ring and never decimated; when it is full the event is dropped and counted.
  bool push_event(const Event& e) noexcept { return events_->push_or_drop(e); }
  // NOT RT-safe: virtual time only, like push_waiting().
  bool push_event_waiting(const Event& e) noexcept;
  std::uint64_t dropped_events() const noexcept { return events_->dropped(); }

  // RT-safe (producer thread). Whether a snapshot and `events` more events fit without waiting: a
  // virtual-time runner waits for this between ticks, so the wait is measured apart from the tick.
  bool has_room(std::size_t events) const noexcept {
    return ring_->size_approx() < SnapshotRing::capacity() &&
           events_->size_approx() + events <= EventRing::capacity();
  }
  // RT-safe, any thread. Whether the publisher is draining the rings (nobody makes room otherwise).
  bool publishing() const noexcept { return publisher_.running(); }

  // RT-safe, any thread.
  std::uint64_t dropped() const noexcept { return ring_->dropped(); }
  PublisherStats stats() const noexcept { return publisher_.stats(); }
  const ChannelNames& channels() const noexcept { return publisher_.channels(); }

 private:
  std::unique_ptr<SnapshotRing> ring_;  // declared first: the publisher holds references to both rings
  std::unique_ptr<EventRing> events_;
  Publisher publisher_;
};

}  // namespace loom::telemetry
