// The non-RT half of telemetry: a thread that drains the snapshot ring in batches and publishes LCM
// messages on the loom's channels, decimated per channel. Everything that can fail or allocate (the
// LCM handle, the thread, the batch buffer) is set up in the constructor, before the loop starts.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "loom/design/design.hpp"
#include "loom/telemetry/channels.hpp"
#include "loom/telemetry/schedule.hpp"
#include "loom/telemetry/snapshot.hpp"
#include "loom/telemetry/spsc_ring.hpp"

namespace lcm {
class LCM;
}
namespace loom::sequencer {
class KnotProgram;
}

namespace loom::telemetry {

// 4096 snapshots: 8 s of buffer at the 2 ms CAN cycle, about 1.3 MB.
// 2 s of ticks at the default 2 ms period: a snapshot holds every axis the controller can have (a
// few KB), so the ring is sized in seconds of publisher lag it absorbs, not in thousands of ticks.
inline constexpr std::size_t kSnapshotRingCapacity = 1024;
using SnapshotRing = SpscRing<Snapshot, kSnapshotRingCapacity>;
// 1024 events: a beat every 0.4 s at the default loom is minutes of slack for a stalled publisher.
inline constexpr std::size_t kEventRingCapacity = 1024;
using EventRing = SpscRing<Event, kEventRingCapacity>;

struct PublisherConfig {
  // "" = LCM's default: $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0 (host only).
  std::string lcm_url;
  std::string loom_id = "loom1";
  hal::AxisLayout axes = hal::AxisLayout::core();  // names for the AXES, STATUS and FAULT messages
  std::string channel_prefix = std::string(kDefaultChannelPrefix);
  Decimation decimation;
  // How long the thread naps when the ring is empty: bounds the added latency, costs a wake-up each.
  std::chrono::microseconds idle_sleep{500};
  std::size_t batch = 256;  // snapshots popped per ring handshake
  // Ceiling on messages per second over all channels; 0 = none. A loop in virtual time produces
  // snapshots ~1000x faster than real time, and LCM 1.3.1 receivers — lcm-logger included — keep only
  // 30 undelivered messages per subscription, so an unpaced burst loses its tail. Pacing here backs up
  // the ring instead, and a virtual-time loop waits (push_waiting) rather than losing data. A real-time
  // loop publishes far below this (about 100 messages/s at the default decimation at 2 ms).
  double max_messages_per_s = 5000.0;
  // The carpet design whose next row DESIGN carries (null: no DESIGN messages). Design rows woven at a
  // snapshot = design_rows_at_start + (its completed rows − counter_rows_at_start).
  std::shared_ptr<const design::Design> design;
  std::uint64_t design_rows_at_start = 0;
  std::uint32_t counter_rows_at_start = 0;
  // The knotting heads' design as magazine slots (the machine's; must outlive the publisher). Non-null
  // with heads: KNOTS goes out with every STATUS and WEAVER requests name their colours. Null: no KNOTS.
  const sequencer::KnotProgram* knot_program = nullptr;
};

struct PublisherStats {
  std::uint64_t snapshots = 0;  // popped from the ring
  std::uint64_t status = 0;     // messages published per channel
  std::uint64_t axes = 0;
  std::uint64_t rt = 0;
  std::uint64_t events = 0;  // BEAT + FAULT + ROW + WEAVER messages published
  std::uint64_t beat = 0;
  std::uint64_t fault = 0;
  std::uint64_t row = 0;
  std::uint64_t weaver = 0;
  std::uint64_t design = 0;
  std::uint64_t knots = 0;  // KNOTS messages (with STATUS, looms with knotting heads)  // DESIGN messages
                            // (not events: sent by the publisher)
  std::uint64_t publish_errors = 0;  // lcm publish() failures (e.g. no multicast route)
};

class Publisher {
 public:
  // Configure-time only. Validates the config and opens LCM on `cfg.lcm_url`; throws
  // std::invalid_argument naming the field and value (the URL for an LCM that will not open).
  // `ring` and `events` must outlive the publisher. Events are published in tick order with the
  // snapshots: an event goes out just before the first snapshot of a later tick (or at stop()).
  Publisher(const PublisherConfig& cfg, SnapshotRing& ring, EventRing& events);
  // Configure-time only. Stops (and drains) if still running.
  ~Publisher();
  Publisher(const Publisher&) = delete;
  Publisher& operator=(const Publisher&) = delete;

  // Configure-time only. Starts the publishing thread; a second call while running does nothing.
  void start();
  // Non-RT. Tells the thread to finish, lets it publish every snapshot in the ring at that moment,
  // joins it. Call it once the loop has stopped pushing; safe to call more than once.
  void stop();
  // RT-safe, any thread. True between start() and stop().
  bool running() const noexcept { return running_.load(std::memory_order_acquire); }

  // RT-safe, any thread. Counters so far (each read atomically, not as one consistent set while running).
  PublisherStats stats() const noexcept;
  // RT-safe, any thread.
  const ChannelNames& channels() const noexcept { return channels_; }

 private:
  void run();
  void drain_once_or_nap();
  std::size_t drain_batch();
  void publish(const Snapshot& s);
  void publish_events_up_to(hal::Tick tick);  // events with tick < `tick`; all of them for kNeverTick
  void publish_event(const Event& e);
  void pace();
  void publish_design(const Snapshot& s, std::int64_t utime);
  template <typename Msg>
  void send(const std::string& channel, const Msg& msg, std::atomic<std::uint64_t>& counter);

  SnapshotRing& ring_;
  EventRing& events_;
  Event pending_{};  // popped from the event ring, waiting for its turn
  bool have_pending_ = false;
  PublisherConfig cfg_;
  ChannelNames channels_;
  ChannelSchedule schedule_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::vector<Snapshot> batch_;
  std::chrono::nanoseconds publish_gap_{0};  // 1 / max_messages_per_s
  std::chrono::steady_clock::time_point next_publish_{};
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  std::atomic<std::uint64_t> n_snapshots_{0}, n_status_{0}, n_axes_{0}, n_rt_{0}, n_errors_{0};
  std::atomic<std::uint64_t> n_beat_{0}, n_fault_{0}, n_row_{0}, n_design_{0}, n_weaver_{0}, n_knots_{0};
  std::uint64_t design_rows_sent_ = UINT64_MAX;  // design rows done in the last DESIGN sent
  std::chrono::steady_clock::time_point design_sent_at_{};
  std::chrono::steady_clock::time_point identity_sent_at_{};
  std::atomic<std::uint64_t> n_identity_{0};
};

}  // namespace loom::telemetry
